// The overlay of strahl view: frame and per-pass timings (top left), the
// module and parameter panel (right), messages and errors (bottom), help.
// The panel is built from the plugin descriptors only (names, types, ranges,
// choices, help), so plugins written later get controls without changes.
#define _GNU_SOURCE
#include "view.h"
#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define C_BG VIEW_RGBA(12, 14, 18, 200)
#define C_TEXT VIEW_RGBA(230, 230, 230, 255)
#define C_DIM VIEW_RGBA(150, 150, 160, 255)
#define C_RAN VIEW_RGBA(120, 230, 120, 255)
#define C_SKIP VIEW_RGBA(240, 210, 90, 255)
#define C_CULL VIEW_RGBA(130, 130, 140, 255)
#define C_ACCENT VIEW_RGBA(90, 160, 255, 255)
#define C_TRACK VIEW_RGBA(60, 64, 74, 255)
#define C_FOCUS VIEW_RGBA(90, 160, 255, 60)
#define C_ERR_BG VIEW_RGBA(110, 20, 20, 220)
#define C_KEY VIEW_RGBA(255, 200, 120, 255)

static bool inside(const view *v, float x, float y, float w, float h) {
    return v->mx >= x && v->mx < x + w && v->my >= y && v->my < y + h;
}

// Word-wrapped text; returns the height used.
static float wrapped(view *v, float x, float y, float w, const char *s, uint32_t color) {
    view_gl *g = &v->gl;
    float line = view_ui_line(g), y0 = y;
    char buf[256];
    while (*s) {
        size_t best = 0, len = 0;
        while (s[len] && s[len] != '\n' && len < sizeof buf - 1) {
            len++;
            snprintf(buf, sizeof buf, "%.*s", (int)len, s);
            if (view_ui_text_width(g, buf) > w) {
                len--;
                break;
            }
            if (s[len] == ' ' || s[len] == 0 || s[len] == '\n') best = len;
        }
        if (!best || s[len] == '\n' || !s[len]) best = len ? len : 1;
        snprintf(buf, sizeof buf, "%.*s", (int)best, s);
        view_ui_text(g, x, y, buf, color);
        y += line;
        s += best;
        while (*s == ' ' || *s == '\n')
            s++;
    }
    return y - y0;
}

// Frame time and the passes of the last frame. Placed at (x, y) or, with
// bottom set, ending at y. Returns its height.
static float stats_box(view *v, float x, float y, bool bottom) {
    view_gl *g = &v->gl;
    const float k = g->scale, line = view_ui_line(g) + 2 * k, pad = 6 * k;
    static const char *names[] = {"ran", "skipped", "culled"};
    const uint32_t colors[] = {C_RAN, C_SKIP, C_CULL};
    char s1[256], s2[256], s[64];
    double fps = v->frame_ms_avg > 0 ? 1000.0 / v->frame_ms_avg : 0;
    snprintf(s1, sizeof s1, "%.1f ms/frame (%.0f fps), world %.1f ms, %dx%d", v->frame_ms_avg, fps,
             v->world_ms, v->fb_w, v->fb_h);
    bool acc_done;
    uint32_t acc = st_world_accumulated(v->world, &acc_done);
    char accs[48] = "";
    if (acc) snprintf(accs, sizeof accs, "  %u frame(s)%s", acc, acc_done ? ", still" : "");
    snprintf(s2, sizeof s2, "god rays: %s  GI: %s  %s  %+.1f EV%s", v->godrays[v->godray],
             view_gi_modes[v->gi], v->cam.fly ? "fly" : "orbit", v->exposure, accs);
    // Columns as wide as their widest entry.
    float cw[2] = {view_ui_text_width(g, "module"), view_ui_text_width(g, "pass")};
    for (int i = 0; i < v->num_rows; i++) {
        float a = view_ui_text_width(g, v->rows[i].module),
              b = view_ui_text_width(g, v->rows[i].pass);
        cw[0] = a > cw[0] ? a : cw[0];
        cw[1] = b > cw[1] ? b : cw[1];
    }
    float cols[5] = {0, cw[0] + 8 * k, 0, 0, 0};
    cols[2] = cols[1] + cw[1] + 8 * k;
    cols[3] = cols[2] + view_ui_text_width(g, "skipped") + 8 * k;
    cols[4] = cols[3] + view_ui_text_width(g, "000.000") + 8 * k;
    float w = cols[4] + view_ui_text_width(g, "median");
    float t1 = view_ui_text_width(g, s1), t2 = view_ui_text_width(g, s2);
    w = (w > t1 ? w : t1) > t2 ? (w > t1 ? w : t1) : t2;
    w += 2 * pad;
    float h = (3 + v->num_rows) * line + 2 * pad - 2 * k;
    if (bottom) y -= h;
    view_ui_rect(g, x, y, w, h, C_BG);
    x += pad, y += pad;
    view_ui_text(g, x, y, s1, C_TEXT);
    y += line;
    view_ui_text(g, x, y, s2, C_DIM);
    y += line;
    const char *head[5] = {"module", "pass", "state", "gpu ms", "median"};
    for (int c = 0; c < 5; c++)
        view_ui_text(g, x + cols[c], y, head[c], C_DIM);
    y += line;
    for (int i = 0; i < v->num_rows; i++, y += line) {
        const view_pass_row *r = &v->rows[i];
        view_ui_text(g, x + cols[0], y, r->module, C_TEXT);
        view_ui_text(g, x + cols[1], y, r->pass, C_TEXT);
        view_ui_text(g, x + cols[2], y, names[r->state], colors[r->state]);
        if (r->state == VIEW_RAN) {
            snprintf(s, sizeof s, r->gpu_ms >= 0 ? "%.3f" : "n/a", r->gpu_ms);
            view_ui_text(g, x + cols[3], y, s, C_TEXT);
        } else {
            view_ui_text(g, x + cols[3], y, "-", C_DIM);
        }
        snprintf(s, sizeof s, "%.3f", r->gpu_med);
        view_ui_text(g, x + cols[4], y, s, C_DIM);
    }
    return h;
}

static void add_widget(view *v, const char *module, const char *param, float x, float y, float w,
                       float h) {
    if (v->num_widgets >= VIEW_MAX_ROWS) return;
    view_widget *wd = &v->widgets[v->num_widgets++];
    snprintf(wd->module, sizeof wd->module, "%s", module);
    snprintf(wd->param, sizeof wd->param, "%s", param);
    wd->x = x, wd->y = y, wd->w = w, wd->h = h;
}

// One parameter row: name, then a slider (float/int/enum) or a checkbox
// (bool) bounded by the declared range. Returns true if the row is hovered.
static bool param_row(view *v, const char *module, int pi, const st_param_def *d, double value,
                      float x, float y, float w) {
    view_gl *g = &v->gl;
    const float k = g->scale, line = view_ui_line(g);
    const float name_w = 100 * k, sx = x + name_w, sw = w - name_w;
    bool focus = !strcmp(v->sel_mod, module) && v->sel_param == pi;
    if (focus) view_ui_rect(g, x - 2 * k, y - 1 * k, w + 4 * k, line + 2 * k, C_FOCUS);
    char name[40];
    snprintf(name, sizeof name, "%.15s%s", d->name, strlen(d->name) > 15 ? "." : "");
    view_ui_text(g, x, y, name, focus ? C_TEXT : C_DIM);
    bool hover = inside(v, x, y, w, line);
    bool on_ctrl = inside(v, sx, y - 1 * k, sw, line + 2 * k);
    add_widget(v, module, d->name, sx, y, sw, line);
    char text[96];
    if (focus && v->editing) {
        view_ui_rect(g, sx, y - 1 * k, sw, line + 2 * k, VIEW_RGBA(20, 20, 24, 255));
        snprintf(text, sizeof text, "%s_", v->edit);
        view_ui_text(g, sx + 3 * k, y, text, C_TEXT);
    } else if (d->type == ST_PARAM_BOOL) {
        view_ui_rect(g, sx, y, line, line, C_TRACK);
        if (value != 0)
            view_ui_rect(g, sx + 2 * k, y + 2 * k, line - 4 * k, line - 4 * k, C_ACCENT);
        view_ui_text(g, sx + line + 4 * k, y, value != 0 ? "on" : "off", C_TEXT);
    } else {
        double t = view_param_to_t(d, value);
        view_ui_rect(g, sx, y, sw, line, C_TRACK);
        view_ui_rect(g, sx, y, (float)(sw * t), line, VIEW_RGBA(50, 100, 170, 255));
        view_ui_rect(g, sx + (float)(sw * t) - 1 * k, y, 2 * k, line, C_ACCENT);
        st_param_format(d, value, text, sizeof text);
        view_ui_text(g, sx + 0.5f * (sw - view_ui_text_width(g, text)), y, text, C_TEXT);
    }
    // Mouse: a press on the control selects the row and starts a drag (bools
    // toggle on press); the drag sets the value from x every frame.
    if (v->mouse_pressed[0] && hover) {
        snprintf(v->sel_mod, sizeof v->sel_mod, "%s", module);
        v->sel_param = pi;
        v->editing = false;
        if (on_ctrl && d->type == ST_PARAM_BOOL) {
            st_err e = {0};
            if (!view_set_param(v, module, d->name, value != 0 ? 0 : 1, &e))
                view_message(v, "%s", e.msg);
        } else if (on_ctrl) {
            snprintf(v->drag_mod, sizeof v->drag_mod, "%s", module);
            v->drag_param = pi;
        }
    }
    if (v->drag_owner == 2 && v->mouse_down[0] && v->drag_param == pi &&
        !strcmp(v->drag_mod, module)) {
        double nv = view_param_from_t(d, (v->mx - sx) / sw);
        if (nv != value) {
            st_err e = {0};
            if (!view_set_param(v, module, d->name, nv, &e)) view_message(v, "%s", e.msg);
        }
    }
    return hover;
}

// Width of the panel for this window.
static float panel_width(const view *v) {
    float k = v->gl.scale, w = 250 * k;
    return w < v->fb_w - 12 * k ? w : v->fb_w - 12 * k;
}

// Module i's row in the panel: its key, checkbox and name; a click switches
// it. Returns whether it is on.
static bool module_row(view *v, int i, float x, float y, float cw) {
    view_gl *g = &v->gl;
    const float k = g->scale, line = view_ui_line(g);
    const char *name = v->mods[i];
    bool on = st_world_has_module(v->world, name);
    char s[16] = "";
    if (i < 10) snprintf(s, sizeof s, "%d", (i + 1) % 10);
    view_ui_text(g, x, y, s, C_DIM);
    view_ui_rect(g, x + 14 * k, y, line, line, C_TRACK);
    if (on) view_ui_rect(g, x + 16 * k, y + 2 * k, line - 4 * k, line - 4 * k, C_ACCENT);
    view_ui_text(g, x + 14 * k + line + 5 * k, y, name, on ? C_TEXT : C_DIM);
    add_widget(v, name, "", x, y, cw, line);
    if (v->mouse_pressed[0] && inside(v, x, y, cw, line)) {
        st_err e = {0};
        if (!view_toggle_module(v, i, &e)) view_message(v, "%s", e.msg);
        on = st_world_has_module(v->world, name);
    }
    return on;
}

// The help of parameter d (NULL: the panel's keys), with its type and
// range; returns its height.
static float help_text(view *v, const st_param_def *d, const char *name, float x, float y,
                       float cw) {
    if (!d)
        return wrapped(v, x, y, cw,
                       "click/drag: set; Up/Down: pick, Left/Right: adjust, Enter: type; H: help",
                       C_DIM);
    char range[160], s[400];
    if (d->type == ST_PARAM_FLOAT || d->type == ST_PARAM_INT)
        snprintf(range, sizeof range, "%s [%g, %g], default %g",
                 d->type == ST_PARAM_INT ? "int" : "float", d->min, d->max, d->def);
    else if (d->type == ST_PARAM_ENUM)
        snprintf(range, sizeof range, "one of %s", d->choices ? d->choices : "");
    else
        snprintf(range, sizeof range, "bool, default %s", d->def != 0 ? "on" : "off");
    snprintf(s, sizeof s, "%s: %s", name, range);
    float h = wrapped(v, x, y, cw, s, C_TEXT);
    return h + wrapped(v, x, y + h, cw, d->help ? d->help : "", C_DIM);
}

// The panel: every switchable module with its key and checkbox, the
// parameters of loaded ones, then the help of the hovered (else focused)
// parameter. Sized to its content, scrolled when taller than the window.
// Returns its bottom edge, kept above max_bottom by scrolling.
static float panel(view *v, float max_bottom) {
    view_gl *g = &v->gl;
    const float k = g->scale, line = view_ui_line(g), row = line + 4 * k, pad = 6 * k;
    float w = panel_width(v), x0 = v->fb_w - w - pad, y0 = pad;
    v->panel_x = x0;
    int bg = g->n;
    view_ui_rect(g, 0, 0, 1, 1, C_BG); // placeholder, sized below
    float x = x0 + pad, cw = w - 2 * pad, top = y0 + pad;
    // Rows: header, modules, parameters of loaded modules.
    int rows = 1;
    for (int i = 0; i < v->num_mods; i++) {
        rows++;
        for (int j = 0; j < st_world_num_modules(v->world); j++)
            if (!strcmp(st_world_module(v->world, j).plugin->name, v->mods[i]))
                rows += st_world_module(v->world, j).plugin->num_params;
    }
    float help_room = 4 * line + pad, list_h = rows * row;
    float max_list = max_bottom - top - pad - help_room - pad;
    if (max_list < row) max_list = row;
    float shown_h = list_h < max_list ? list_h : max_list;
    float bottom = top + shown_h;
    bool over = inside(v, x0, y0, w, shown_h + help_room + 2 * pad);
    if (over && v->wheel != 0) v->panel_scroll -= (float)v->wheel * 3 * row;
    float max_scroll = list_h - shown_h;
    v->panel_scroll = v->panel_scroll > max_scroll ? max_scroll
                      : v->panel_scroll < 0        ? 0
                                                   : v->panel_scroll;
    // Row y positions are snapped to whole rows so clipping never cuts text.
    float y = top - floorf(v->panel_scroll / row) * row;
    const st_param_def *help = NULL;
    char helpname[160] = "";
#define VISIBLE (y >= top - 0.5f && y + row <= bottom + 0.5f)
    if (VISIBLE) view_ui_text(g, x, y, "modules (keys) and parameters", C_TEXT);
    y += row;
    for (int i = 0; i < v->num_mods; i++) {
        const char *name = v->mods[i];
        bool on = VISIBLE ? module_row(v, i, x, y, cw) : st_world_has_module(v->world, name);
        y += row;
        if (!on) continue;
        int m = -1;
        for (int j = 0; j < st_world_num_modules(v->world); j++)
            if (!strcmp(st_world_module(v->world, j).plugin->name, name)) m = j;
        if (m < 0) continue;
        st_module_info mi = st_world_module(v->world, m);
        for (int p = 0; p < mi.plugin->num_params; p++, y += row) {
            if (!VISIBLE) continue;
            const st_param_def *d = &mi.plugin->params[p];
            bool hover = param_row(v, name, p, d, mi.params[p], x + 14 * k, y, cw - 14 * k);
            bool focus = !strcmp(v->sel_mod, name) && v->sel_param == p;
            if (hover || (focus && !help)) {
                help = d;
                snprintf(helpname, sizeof helpname, "%s.%s", name, d->name);
            }
        }
    }
#undef VISIBLE
    if (max_scroll > 0) { // scroll bar
        float bar = shown_h * shown_h / list_h;
        view_ui_rect(g, x0 + w - 3 * k, top + (shown_h - bar) * v->panel_scroll / max_scroll, 2 * k,
                     bar, C_DIM);
    }
    // Help of the hovered (else focused) parameter, with its type and range.
    float hy = bottom + pad;
    view_ui_rect(g, x, hy - pad * 0.5f, cw, 1 * k, C_TRACK);
    hy += help_text(v, help, helpname, x, hy, cw);
    float h = hy + pad - y0;
    view_ui_patch_rect(g, bg, x0, y0, w, h);
    v->over_panel = inside(v, x0, y0, w, h);
    if (v->drag_owner == 2 && !v->mouse_down[0]) v->drag_param = -1;
    return y0 + h;
}

// Height of a wrapped text box of width w (laid out, then discarded).
static float measure(view *v, float w, const char *text) {
    int n = v->gl.n;
    float h = wrapped(v, 0, 0, w, text, C_TEXT);
    v->gl.n = n;
    return h;
}

// Transient message and sticky error at the bottom left, full width unless
// that would run into the panel; returns the top edge of what was drawn.
static float messages(view *v, float panel_x, float panel_bottom) {
    view_gl *g = &v->gl;
    const float k = g->scale, pad = 6 * k;
    bool msg = v->message[0] && (v->script || glfwGetTime() < v->message_until);
    float w = v->fb_w - 2 * pad;
    for (int pass = 0; pass < 2; pass++) {
        float h = 0;
        if (msg) h += measure(v, w - 2 * pad, v->message) + 3 * pad;
        if (v->error[0]) h += measure(v, w - 2 * pad, v->error) + 3 * pad;
        if (v->fb_h - pad - h >= panel_bottom || panel_x - 3 * pad < 150 * k) break;
        w = panel_x - 2 * pad;
    }
    float y = v->fb_h - pad;
    if (msg) {
        float h = measure(v, w - 2 * pad, v->message);
        float tw = view_ui_text_width(g, v->message) + 2 * pad;
        y -= h + 2 * pad;
        view_ui_rect(g, pad, y, tw < w ? tw : w, h + 2 * pad, C_BG);
        wrapped(v, 2 * pad, y + pad, w - 2 * pad, v->message, C_TEXT);
        y -= pad;
    }
    if (v->error[0]) {
        float h = measure(v, w - 2 * pad, v->error);
        y -= h + 2 * pad;
        view_ui_rect(g, pad, y, w, h + 2 * pad, C_ERR_BG);
        wrapped(v, 2 * pad, y + pad, w - 2 * pad, v->error, C_TEXT);
        y -= pad;
    }
    return y;
}

// Keys and what they do, two columns (the help text separates them by a tab).
static void help_box(view *v) {
    view_gl *g = &v->gl;
    const float k = g->scale, pad = 10 * k, line = view_ui_line(g) + 1 * k;
    const char *text = view_help_text(v);
    float kw = 0, dw = 0;
    int lines = 0;
    char buf[256];
    for (const char *c = text; *c; lines++) {
        size_t l = strcspn(c, "\n"), t = strcspn(c, "\t");
        snprintf(buf, sizeof buf, "%.*s", (int)(t < l ? t : l), c);
        float a = view_ui_text_width(g, buf);
        kw = a > kw ? a : kw;
        if (t < l) {
            snprintf(buf, sizeof buf, "%.*s", (int)(l - t - 1), c + t + 1);
            float b = view_ui_text_width(g, buf);
            dw = b > dw ? b : dw;
        }
        c += l + (c[l] == '\n');
    }
    float w = kw + 12 * k + dw + 2 * pad, h = lines * line + 2 * pad;
    float x = 0.5f * (v->fb_w - w), y = 0.5f * (v->fb_h - h);
    if (x < 0) x = 0;
    if (y < 0) y = 0;
    view_ui_rect(g, x, y, w, h, VIEW_RGBA(12, 14, 18, 235));
    float ly = y + pad;
    for (const char *c = text; *c; ly += line) {
        size_t l = strcspn(c, "\n"), t = strcspn(c, "\t");
        snprintf(buf, sizeof buf, "%.*s", (int)(t < l ? t : l), c);
        view_ui_text(g, x + pad, ly, buf, ly == y + pad ? C_ACCENT : C_KEY);
        if (t < l) {
            snprintf(buf, sizeof buf, "%.*s", (int)(l - t - 1), c + t + 1);
            view_ui_text(g, x + pad + kw + 12 * k, ly, buf, C_TEXT);
        }
        c += l + (c[l] == '\n');
    }
}

void view_overlay(view *v) {
    const float k = v->gl.scale, pad = 6 * k, line = view_ui_line(&v->gl);
    v->over_panel = false;
    v->num_widgets = 0;
    // Stats top left, panel top right. When the window is too narrow for
    // both, the stats box moves to the bottom left and the panel scrolls in
    // the height above it. The choice depends on the window only, so the
    // panel's rows stay put while passes come and go.
    bool beside = !v->show_stats || !v->show_panel || v->fb_w >= panel_width(v) + 330 * k + 3 * pad;
    float max_bottom = v->fb_h, stats_h = 0;
    if (v->show_stats && !beside) {
        int n = v->gl.n;
        stats_h = stats_box(v, 0, 0, false);
        v->gl.n = n;
        float room = v->fb_h - stats_h - 2 * (line + 3 * pad) - pad;
        max_bottom = room > 0.5f * v->fb_h ? room : 0.5f * v->fb_h;
    }
    float panel_bottom = v->show_panel ? panel(v, max_bottom) : 0;
    float px = v->show_panel ? v->panel_x : (float)v->fb_w;
    int n = v->gl.n;
    float msg_top = messages(v, px, panel_bottom);
    v->gl.n = n;
    if (v->show_stats) stats_box(v, pad, beside ? pad : msg_top, !beside);
    // Last, so an error is never hidden under the other boxes.
    messages(v, px, panel_bottom);
    if (v->show_help) help_box(v);
}
