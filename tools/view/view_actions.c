// strahl view actions: everything a key, the panel or a script line can do.
// Each action reports failures through st_err and leaves the world usable.
#define _GNU_SOURCE
#include "st_file.h"
#include "view.h"
#include <GLFW/glfw3.h>
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

const char *const view_gi_modes[5] = {"off", "direct", "indirect", "combined", "atlas"};

void view_message(view *v, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->message, sizeof v->message, fmt, ap);
    va_end(ap);
    v->message_until = glfwGetTime() + 5.0;
    // Also on stdout: scripted sessions and their tests read it there.
    printf("strahl view: %s\n", v->message);
    fflush(stdout);
}

static int cmp_name(const void *a, const void *b) {
    return strcmp(a, b);
}
static int loaded_index(const view *v, const char *name);

static bool installed(const view *v, const char *name) {
    for (int i = 0; i < v->num_mods; i++)
        if (!strcmp(v->mods[i], name)) return true;
    return false;
}

void view_refresh_modules(view *v) {
    char names[64][ST_NAME_MAX];
    int n = st_plugin_list(names, 64);
    for (int i = 0; i < st_world_num_modules(v->world) && n < 64; i++) {
        const char *m = st_world_module(v->world, i).plugin->name;
        bool dup = false;
        for (int k = 0; k < n; k++)
            dup |= !strcmp(names[k], m);
        if (!dup) snprintf(names[n++], ST_NAME_MAX, "%s", m);
    }
    qsort(names, (size_t)n, ST_NAME_MAX, cmp_name);
    v->num_mods = n < VIEW_MAX_MODS ? n : VIEW_MAX_MODS;
    for (int i = 0; i < v->num_mods; i++)
        snprintf(v->mods[i], ST_NAME_MAX, "%.*s", ST_NAME_MAX - 1, names[i]);
    view_classify_modules(v);
    // The cycles follow what is loaded (the scene may load toth itself).
    v->godray = 0;
    for (int k = 1; k < v->num_godrays && !v->godray; k++)
        if (st_world_has_module(v->world, v->godrays[k])) v->godray = k;
    v->gi = 0;
    int m = v->gi_module[0] ? loaded_index(v, v->gi_module) : -1;
    if (m >= 0) {
        st_module_info mi = st_world_module(v->world, m);
        int pi = view_gi_display_param(mi.plugin);
        v->gi = 3; // without a display switch the module shows its combined result
        if (pi >= 0) {
            char c[ST_NAME_MAX];
            st_param_choice(&mi.plugin->params[pi], (int)mi.params[pi], c, sizeof c);
            for (int k = 1; k < 5; k++)
                if (!strncmp(c, view_gi_modes[k], strlen(view_gi_modes[k]))) v->gi = k;
        }
    }
}

static int loaded_index(const view *v, const char *name) {
    for (int i = 0; i < st_world_num_modules(v->world); i++)
        if (!strcmp(st_world_module(v->world, i).plugin->name, name)) return i;
    return -1;
}

static void remember(view *v, const char *name) {
    int m = loaded_index(v, name);
    if (m < 0) return;
    st_module_info mi = st_world_module(v->world, m);
    view_memory *slot = NULL;
    for (int i = 0; i < v->num_memory && !slot; i++)
        if (!strcmp(v->memory[i].name, name)) slot = &v->memory[i];
    if (!slot && v->num_memory < VIEW_MAX_MODS) slot = &v->memory[v->num_memory++];
    if (!slot) return;
    snprintf(slot->name, sizeof slot->name, "%s", name);
    slot->num_params =
        mi.plugin->num_params < ST_MAX_PARAMS ? mi.plugin->num_params : ST_MAX_PARAMS;
    memcpy(slot->params, mi.params, (size_t)slot->num_params * sizeof(double));
}

static void restore(view *v, const char *name) {
    int m = loaded_index(v, name);
    if (m < 0) return;
    const st_plugin *p = st_world_module(v->world, m).plugin;
    for (int i = 0; i < v->num_memory; i++) {
        if (strcmp(v->memory[i].name, name) ||
            v->memory[i].num_params !=
                (p->num_params < ST_MAX_PARAMS ? p->num_params : ST_MAX_PARAMS))
            continue;
        for (int k = 0; k < v->memory[i].num_params; k++) {
            st_err e = {0};
            st_world_set_param(v->world, name, p->params[k].name, v->memory[i].params[k], &e);
        }
    }
}

bool view_enable(view *v, const char *module, bool on, st_err *err) {
    if (st_world_has_module(v->world, module) == on) return true;
    if (on && !installed(v, module)) {
        char dirs[2048];
        st_plugin_dirs(dirs, sizeof dirs);
        return st_fail(err, ST_ERR_INPUT, "module '%s' is not installed (searched %s)", module,
                       dirs);
    }
    bool before[VIEW_MAX_MODS];
    for (int i = 0; i < v->num_mods; i++)
        before[i] = st_world_has_module(v->world, v->mods[i]);
    if (!on) remember(v, module);
    if (!st_world_enable(v->world, module, on, err)) {
        // The world rolls a failed switch-on back; a switch-off whose shader
        // rebuild failed still removed the module. Show what is loaded now.
        view_refresh_modules(v);
        return false;
    }
    char also[256] = "";
    for (int i = 0; i < v->num_mods; i++) {
        if (before[i] || !st_world_has_module(v->world, v->mods[i])) continue;
        restore(v, v->mods[i]);
        if (strcmp(v->mods[i], module)) {
            size_t l = strlen(also);
            snprintf(also + l, sizeof also - l, "%s%s", l ? ", " : "", v->mods[i]);
        }
    }
    view_refresh_modules(v);
    if (also[0])
        view_message(v, "%s on (needs %s: switched on)", module, also);
    else
        view_message(v, "%s %s", module, on ? "on" : "off");
    return true;
}

bool view_toggle_module(view *v, int index, st_err *err) {
    if (index < 0 || index >= v->num_mods)
        return st_fail(err, ST_ERR_INPUT, "no module #%d (%d installed)", index + 1, v->num_mods);
    return view_enable(v, v->mods[index], !st_world_has_module(v->world, v->mods[index]), err);
}

// The next technique in off > the god-ray techniques (view_kinds.c: by
// name, today mitchell > sousa > toth) that the scene accepts (mitchell and
// sousa refuse spot lights): a refusal moves on to the next one instead of
// leaving the cycle stuck on it.
bool view_cycle_godrays(view *v, st_err *err) {
    char skipped[512] = "";
    int n = v->num_godrays;
    for (int step = 1; step <= n; step++) {
        int c = (v->godray + step) % n;
        // The names are copied: switching modules refreshes v->godrays.
        char name[ST_NAME_MAX], off[ST_NAME_MAX];
        snprintf(name, sizeof name, "%s", v->godrays[c]);
        st_err refused = {0};
        for (int k = 1; k < n; k++) {
            snprintf(off, sizeof off, "%s", v->godrays[k]);
            if (k != c && !view_enable(v, off, false, err)) return false;
        }
        if (c == 0 || view_enable(v, name, true, &refused)) {
            v->godray = c;
            if (skipped[0])
                view_message(v, "god rays: %s (skipped: %s)", name, skipped);
            else
                view_message(v, "god rays: %s", name);
            return true;
        }
        size_t l = strlen(skipped);
        snprintf(skipped + l, sizeof skipped - l, "%s%s: %.160s", l ? "; " : "", name, refused.msg);
    }
    return st_fail(err, ST_ERR_RUNTIME, "god rays: no technique could be switched on (%s)",
                   skipped);
}

// Choice index of a GI mode: exact name, or a choice starting with it
// ("atlas" matches "atlas_view"); -1 if the module has none.
static int gi_choice(const st_param_def *d, const char *mode) {
    int prefix = -1;
    for (int k = 0; k < st_param_num_choices(d); k++) {
        char c[ST_NAME_MAX];
        st_param_choice(d, k, c, sizeof c);
        if (!strcmp(c, mode)) return k;
        if (prefix < 0 && !strncmp(c, mode, strlen(mode))) prefix = k;
    }
    return prefix;
}

bool view_cycle_gi(view *v, st_err *err) {
    if (!v->gi_module[0]) {
        v->gi = 0;
        view_message(v, "GI display: off (no GI module is installed)");
        return true;
    }
    char gi_module[ST_NAME_MAX];
    snprintf(gi_module, sizeof gi_module, "%s", v->gi_module);
    st_plugin_lib *lib = st_plugin_open(gi_module, err);
    if (!lib) return false;
    const st_plugin *p = st_plugin_desc(lib);
    int pi = view_gi_display_param(p);
    int choice[5] = {-1, -1, -1, -1, -1};
    char pname[ST_NAME_MAX] = "";
    if (pi >= 0) {
        snprintf(pname, sizeof pname, "%s", p->params[pi].name);
        for (int m = 1; m < 5; m++)
            choice[m] = gi_choice(&p->params[pi], view_gi_modes[m]);
    }
    st_plugin_close(lib);
    char skipped[256] = "";
    int target = 0;
    for (int step = 1; step <= 5; step++) {
        int c = (v->gi + step) % 5;
        // Without a display switch, "combined" is the module's only output.
        if (c == 0 || choice[c] >= 0 || (pi < 0 && c == 3)) {
            target = c;
            break;
        }
        size_t l = strlen(skipped);
        snprintf(skipped + l, sizeof skipped - l, "%s%s", l ? ", " : "", view_gi_modes[c]);
    }
    if (!view_enable(v, gi_module, target != 0, err)) return false;
    if (target && pi >= 0 && !st_world_set_param(v->world, gi_module, pname, choice[target], err))
        return false;
    v->gi = target;
    if (skipped[0])
        view_message(v, "GI display: %s (%s.%s has no choice for: %s)", view_gi_modes[target],
                     gi_module, pi >= 0 ? pname : "<display>", skipped);
    else
        view_message(v, "GI display: %s", view_gi_modes[target]);
    return true;
}

bool view_set_param(view *v, const char *module, const char *param, double value, st_err *err) {
    if (!st_world_set_param(v->world, module, param, value, err)) return false;
    int m = loaded_index(v, module);
    const st_plugin *p = st_world_module(v->world, m).plugin;
    const st_param_def *d = &p->params[st_param_index(p, param)];
    char text[ST_NAME_MAX];
    st_param_format(d, value, text, sizeof text);
    view_message(v, "%s.%s = %s", module, param, text);
    // The GI cycle follows a display switch set by hand.
    if (!strcmp(module, v->gi_module) && d->type == ST_PARAM_ENUM &&
        view_gi_display_param(p) == st_param_index(p, param)) {
        char c[ST_NAME_MAX];
        st_param_choice(d, (int)value, c, sizeof c);
        for (int k = 1; k < 5; k++)
            if (!strncmp(c, view_gi_modes[k], strlen(view_gi_modes[k]))) v->gi = k;
    }
    return true;
}

bool view_set_param_text(view *v, const char *module, const char *param, const char *text,
                         st_err *err) {
    int m = loaded_index(v, module);
    if (m < 0) return st_fail(err, ST_ERR_INPUT, "module '%s' is not loaded", module);
    const st_plugin *p = st_world_module(v->world, m).plugin;
    int k = st_param_index(p, param);
    if (k < 0)
        return st_fail(err, ST_ERR_INPUT, "module '%s' has no parameter '%s'", module, param);
    const st_param_def *d = &p->params[k];
    double value;
    char *e;
    if (d->type == ST_PARAM_BOOL && (!strcasecmp(text, "true") || !strcasecmp(text, "on"))) {
        value = 1;
    } else if (d->type == ST_PARAM_BOOL &&
               (!strcasecmp(text, "false") || !strcasecmp(text, "off"))) {
        value = 0;
    } else {
        value = -1;
        if (d->type == ST_PARAM_ENUM)
            for (int c = 0; c < st_param_num_choices(d) && value < 0; c++) {
                char name[ST_NAME_MAX];
                st_param_choice(d, c, name, sizeof name);
                if (!strcmp(name, text)) value = c;
            }
        if (value < 0) {
            value = strtod(text, &e);
            if (e == text || *e)
                return st_fail(err, ST_ERR_INPUT, "%s.%s: '%s' is not a %s", module, param, text,
                               d->type == ST_PARAM_ENUM   ? "choice"
                               : d->type == ST_PARAM_BOOL ? "bool"
                                                          : "number");
        }
    }
    return view_set_param(v, module, param, value, err);
}

bool view_reload(view *v) {
    st_err err = {0};
    if (!st_world_reload_shaders(v->world, &err)) {
        snprintf(v->error, sizeof v->error, "shader reload failed, old shaders kept: %.980s",
                 err.msg);
        fprintf(stderr, "strahl view: %s\n", v->error);
        return false;
    }
    v->error[0] = 0;
    view_message(v, "shaders reloaded from %s", st_shader_root());
    return true;
}

bool view_check_output(const view *v, const char *what, const char *path, const char *const *exts,
                       st_err *err) {
    const char *inputs[] = {v->scene_path, v->script_path, NULL};
    return st_check_output(what, path, exts, inputs, err) &&
           st_scene_check_output(v->scene, what, path, err);
}

bool view_screenshot(view *v, const char *base, st_err *err) {
    char stem[1024];
    snprintf(stem, sizeof stem, "%s", base);
    char *dot = strrchr(stem, '.');
    if (dot && (!strcasecmp(dot, ".exr") || !strcasecmp(dot, ".png"))) *dot = 0;
    st_image img = {0};
    if (!st_world_read(v->world, &img, err)) return false;
    char exr[1100], png[1100];
    snprintf(exr, sizeof exr, "%s.exr", stem);
    snprintf(png, sizeof png, "%s.png", stem);
    static const char *const exr_ext[] = {"exr", NULL}, *const png_ext[] = {"png", NULL};
    if (!view_check_output(v, "screenshot", exr, exr_ext, err) ||
        !view_check_output(v, "screenshot", png, png_ext, err)) {
        st_image_free(&img);
        return false;
    }
    bool ok = st_image_write(exr, &img, 0, err) && st_image_write(png, &img, v->exposure, err);
    if (ok) view_message(v, "screenshot %dx%d: %s, %s", img.width, img.height, exr, png);
    st_image_free(&img);
    return ok;
}

static void json_str(FILE *f, const char *s) {
    fputc('"', f);
    for (; s && *s; s++) {
        if (*s == '"' || *s == '\\')
            fprintf(f, "\\%c", *s);
        else if ((unsigned char)*s < 0x20)
            fprintf(f, "\\u%04x", *s);
        else
            fputc(*s, f);
    }
    fputc('"', f);
}

bool view_write_stats(view *v, const char *path, st_err *err) {
    static const char *const exts[] = {"json", NULL};
    if (!view_check_output(v, "stats", path, exts, err)) return false;
    st_outfile o;
    FILE *f = st_out_begin(&o, path, err) ? st_out_stream(&o, err) : NULL;
    if (!f) {
        st_out_abort(&o);
        return false;
    }
    static const char *states[] = {"ran", "skipped", "culled"};
    fprintf(f,
            "{\"frame\": %llu, \"width\": %d, \"height\": %d, \"frame_ms\": %.4f, \"world_ms\": "
            "%.4f,\n",
            (unsigned long long)v->frames, v->fb_w, v->fb_h, v->frame_ms, v->world_ms);
    fprintf(f,
            " \"god_rays\": \"%s\", \"gi_display\": \"%s\", \"exposure\": %g, \"camera\": "
            "{\"position\": [%.9g, %.9g, %.9g], \"target\": [%.9g, %.9g, %.9g]},\n",
            v->godrays[v->godray], view_gi_modes[v->gi], v->exposure, v->cam.pos[0], v->cam.pos[1],
            v->cam.pos[2], v->cam.target[0], v->cam.target[1], v->cam.target[2]);
    bool acc_done;
    uint32_t acc = st_world_accumulated(v->world, &acc_done);
    fprintf(f, " \"accumulated\": %u, \"accumulation_done\": %s,\n", acc,
            acc_done ? "true" : "false");
    fprintf(f, " \"error\": ");
    json_str(f, v->error);
    fprintf(f, ",\n \"modules\": [");
    for (int i = 0; i < st_world_num_modules(v->world); i++) {
        st_module_info mi = st_world_module(v->world, i);
        fprintf(f, "%s\n  {\"name\": ", i ? "," : "");
        json_str(f, mi.plugin->name);
        fprintf(f, ", \"params\": {");
        for (int k = 0; k < mi.plugin->num_params; k++) {
            fprintf(f, "%s", k ? ", " : "");
            json_str(f, mi.plugin->params[k].name);
            fprintf(f, ": %.17g", mi.params[k]);
        }
        fprintf(f, "}}");
    }
    fprintf(f, "],\n \"passes\": [");
    for (int i = 0; i < v->num_rows; i++) {
        const view_pass_row *r = &v->rows[i];
        fprintf(f, "%s\n  {\"module\": ", i ? "," : "");
        json_str(f, r->module);
        fprintf(f, ", \"pass\": ");
        json_str(f, r->pass);
        fprintf(f,
                ", \"state\": \"%s\", \"gpu_ms\": %.4f, \"cpu_ms\": %.4f, \"gpu_ms_median\": %.4f, "
                "\"runs\": %u, \"skipped\": %u, \"culled\": %u}",
                states[r->state], r->gpu_ms, r->cpu_ms, r->gpu_med, r->runs, r->skipped, r->culled);
    }
    fprintf(f, "\n],\n \"widgets\": [");
    for (int i = 0; i < v->num_widgets; i++) {
        const view_widget *wd = &v->widgets[i];
        fprintf(f, "%s\n  {\"module\": ", i ? "," : "");
        json_str(f, wd->module);
        fprintf(f, ", \"param\": ");
        json_str(f, wd->param);
        fprintf(f, ", \"x\": %.1f, \"y\": %.1f, \"w\": %.1f, \"h\": %.1f}", wd->x, wd->y, wd->w,
                wd->h);
    }
    fprintf(f, "\n]}\n");
    return st_out_commit(&o, err);
}

void view_set_camera(view *v, const float pos[3], const float target[3]) {
    memcpy(v->cam.pos, pos, sizeof v->cam.pos);
    memcpy(v->cam.target, target, sizeof v->cam.target);
    v->cam_dirty = true;
}

// ---- keys -------------------------------------------------------------------

// The panel's keyboard focus walks the parameters of loaded modules in panel
// order; returns false if there are none.
static bool focus_step(view *v, int dir) {
    char mods[VIEW_MAX_MODS * ST_MAX_PARAMS][ST_NAME_MAX];
    int params[VIEW_MAX_MODS * ST_MAX_PARAMS], n = 0, cur = -1;
    for (int i = 0; i < v->num_mods; i++) {
        int m = loaded_index(v, v->mods[i]);
        if (m < 0) continue;
        const st_plugin *p = st_world_module(v->world, m).plugin;
        for (int k = 0; k < p->num_params; k++) {
            if (!strcmp(v->mods[i], v->sel_mod) && k == v->sel_param) cur = n;
            snprintf(mods[n], ST_NAME_MAX, "%s", v->mods[i]);
            params[n++] = k;
        }
    }
    if (!n) return false;
    int next = cur < 0 ? (dir >= 0 ? 0 : n - 1) : (cur + dir + n) % n;
    snprintf(v->sel_mod, sizeof v->sel_mod, "%.*s", ST_NAME_MAX - 1, mods[next]);
    v->sel_param = params[next];
    return true;
}

static const st_param_def *focused(view *v, double *value) {
    int m = loaded_index(v, v->sel_mod);
    if (m < 0) return NULL;
    st_module_info mi = st_world_module(v->world, m);
    if (v->sel_param < 0 || v->sel_param >= mi.plugin->num_params) return NULL;
    *value = mi.params[v->sel_param];
    return &mi.plugin->params[v->sel_param];
}

// Left/right on the focused parameter: 1% of the slider (10% with Shift),
// at least one step for ints, one choice for enums; bools toggle.
static bool nudge(view *v, int dir, bool coarse, st_err *err) {
    double val;
    const st_param_def *d = focused(v, &val);
    if (!d && !focus_step(v, 1)) return true;
    if (!d) d = focused(v, &val);
    double nv;
    if (d->type == ST_PARAM_BOOL) {
        nv = val != 0 ? 0 : 1;
    } else if (d->type == ST_PARAM_ENUM) {
        int n = st_param_num_choices(d);
        nv = fmod(val + dir + n, n);
    } else {
        double t = view_param_to_t(d, val) + dir * (coarse ? 0.1 : 0.01);
        nv = view_param_from_t(d, t < 0 ? 0 : t > 1 ? 1 : t);
        if (d->type == ST_PARAM_INT) {
            nv = floor(nv + 0.5);
            if (nv == val) nv = val + dir;
        }
        nv = nv < d->min ? d->min : nv > d->max ? d->max : nv;
    }
    return view_set_param(v, v->sel_mod, d->name, nv, err);
}

static bool edit_key(view *v, int key, st_err *err) {
    if (key == GLFW_KEY_ESCAPE) {
        v->editing = false;
    } else if (key == GLFW_KEY_BACKSPACE) {
        v->edit_fresh = false;
        size_t l = strlen(v->edit);
        if (l) v->edit[l - 1] = 0;
    } else if (key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) {
        v->editing = false;
        double val;
        const st_param_def *d = focused(v, &val);
        if (d) return view_set_param_text(v, v->sel_mod, d->name, v->edit, err);
    }
    return true;
}

void view_char(view *v, unsigned c) {
    if (v->editing && v->edit_fresh) v->edit[0] = 0;
    v->edit_fresh = false;
    size_t l = strlen(v->edit);
    if (v->editing && c >= 0x20 && c < 0x7f && l + 1 < sizeof v->edit) {
        v->edit[l] = (char)c;
        v->edit[l + 1] = 0;
    }
}

// The panel's keys: pick, nudge, toggle, type or reset the focused
// parameter. *done: the key is one of them.
static bool param_key(view *v, int key, bool shift, bool *done, st_err *err) {
    double val;
    const st_param_def *d;
    *done = true;
    switch (key) {
    case GLFW_KEY_UP:
        focus_step(v, -1);
        return true;
    case GLFW_KEY_DOWN:
        focus_step(v, 1);
        return true;
    case GLFW_KEY_LEFT:
        return nudge(v, -1, shift, err);
    case GLFW_KEY_RIGHT:
        return nudge(v, 1, shift, err);
    case GLFW_KEY_SPACE:
        if ((d = focused(v, &val)) && (d->type == ST_PARAM_BOOL || d->type == ST_PARAM_ENUM))
            return nudge(v, 1, false, err);
        return true;
    case GLFW_KEY_ENTER:
    case GLFW_KEY_KP_ENTER:
        if ((d = focused(v, &val)) || (focus_step(v, 1) && (d = focused(v, &val)))) {
            v->editing = v->edit_fresh = true;
            if (d->type == ST_PARAM_ENUM || d->type == ST_PARAM_BOOL)
                st_param_format(d, val, v->edit, sizeof v->edit);
            else
                snprintf(v->edit, sizeof v->edit, "%.6g", val);
        }
        return true;
    case GLFW_KEY_DELETE:
        if ((d = focused(v, &val))) return view_set_param(v, v->sel_mod, d->name, d->def, err);
        return true;
    default:
        *done = false;
        return true;
    }
}

// The camera, render size and exposure keys. *done: the key is one of them.
static void camera_key(view *v, int key, bool *done) {
    *done = true;
    switch (key) {
    case GLFW_KEY_K:
        v->fixed_size = !v->fixed_size;
        if (v->fixed_size)
            view_message(v,
                         "rendering at the scene's size %dx%d (scaled to the window; screenshots "
                         "at that size)",
                         v->render_w, v->render_h);
        else
            view_message(v, "rendering at the window's size");
        return;
    case GLFW_KEY_C:
        v->cam.fly = !v->cam.fly;
        view_message(v, "camera: %s", v->cam.fly ? "fly (drag to look, WASD QE to move)" : "orbit");
        return;
    case GLFW_KEY_R:
        v->cam = v->cam_home;
        v->cam_dirty = true;
        view_message(v, "camera reset to the scene's");
        return;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD:
        v->exposure += 0.5f;
        view_message(v, "exposure %+.1f EV", v->exposure);
        return;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
        v->exposure -= 0.5f;
        view_message(v, "exposure %+.1f EV", v->exposure);
        return;
    default:
        *done = false;
    }
}

bool view_key(view *v, int key, int mods, st_err *err) {
    bool shift = mods & GLFW_MOD_SHIFT, done;
    if (v->editing) return edit_key(v, key, err);
    if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) return view_toggle_module(v, key - GLFW_KEY_1, err);
    if (key == GLFW_KEY_0) return view_toggle_module(v, 9, err);
    bool ok = param_key(v, key, shift, &done, err);
    if (done) return ok;
    camera_key(v, key, &done);
    if (done) return true;
    switch (key) {
    case GLFW_KEY_G:
        return view_cycle_godrays(v, err);
    case GLFW_KEY_I:
        return view_cycle_gi(v, err);
    case GLFW_KEY_F5:
        view_reload(v);
        return true;
    case GLFW_KEY_P:
    case GLFW_KEY_F12: {
        char base[1000];
        snprintf(base, sizeof base, "%.960s/strahl-view-%03d", v->shot_dir, ++v->shot_counter);
        if (!view_screenshot(v, base, err)) return false;
        // The window with the overlay, written after the next frame is drawn.
        snprintf(v->capture_path, sizeof v->capture_path, "%s-window.png", base);
        static const char *const png_ext[] = {"png", NULL};
        if (!view_check_output(v, "capture", v->capture_path, png_ext, err)) return false;
        v->want_capture = true;
        return true;
    }
    case GLFW_KEY_TAB:
        v->show_panel = !v->show_panel;
        return true;
    case GLFW_KEY_O:
        v->show_stats = !v->show_stats;
        return true;
    case GLFW_KEY_H:
    case GLFW_KEY_F1:
        v->show_help = !v->show_help;
        return true;
    case GLFW_KEY_ESCAPE:
        if (v->show_help)
            v->show_help = false;
        else
            v->quit = true;
        return true;
    default:
        return true; // unbound keys do nothing
    }
}

int view_key_from_name(const char *name, int *mods) {
    *mods = 0;
    for (;;) {
        if (!strncasecmp(name, "shift+", 6))
            *mods |= GLFW_MOD_SHIFT, name += 6;
        else if (!strncasecmp(name, "ctrl+", 5))
            *mods |= GLFW_MOD_CONTROL, name += 5;
        else
            break;
    }
    if (strlen(name) == 1 && isalnum((unsigned char)name[0]))
        return toupper((unsigned char)name[0]);
    if ((name[0] == 'F' || name[0] == 'f') && isdigit((unsigned char)name[1])) {
        int n = atoi(name + 1);
        if (n >= 1 && n <= 25) return GLFW_KEY_F1 + n - 1;
    }
    static const struct {
        const char *name;
        int key;
    } named[] = {
        {"tab", GLFW_KEY_TAB},
        {"enter", GLFW_KEY_ENTER},
        {"return", GLFW_KEY_ENTER},
        {"escape", GLFW_KEY_ESCAPE},
        {"esc", GLFW_KEY_ESCAPE},
        {"space", GLFW_KEY_SPACE},
        {"up", GLFW_KEY_UP},
        {"down", GLFW_KEY_DOWN},
        {"left", GLFW_KEY_LEFT},
        {"right", GLFW_KEY_RIGHT},
        {"backspace", GLFW_KEY_BACKSPACE},
        {"delete", GLFW_KEY_DELETE},
        {"plus", GLFW_KEY_EQUAL},
        {"=", GLFW_KEY_EQUAL},
        {"+", GLFW_KEY_EQUAL},
        {"minus", GLFW_KEY_MINUS},
        {"-", GLFW_KEY_MINUS},
    };
    for (size_t i = 0; i < sizeof named / sizeof named[0]; i++)
        if (!strcasecmp(name, named[i].name)) return named[i].key;
    return -1;
}

// The G line names the god-ray techniques found (view_kinds.c).
const char *view_help_text(const view *v) {
    static char text[2048];
    char cycle[512] = "off";
    for (int i = 1; i < v->num_godrays; i++) {
        size_t l = strlen(cycle);
        snprintf(cycle + l, sizeof cycle - l, " > %s", v->godrays[i]);
    }
    snprintf(text, sizeof text,
             "strahl view\tkeys\n"
             "1-9, 0\tswitch module #n on/off (numbers in the panel)\n"
             "G\tgod rays: %s\n"
             "I\tGI display: off > direct > indirect > combined > atlas\n"
             "left drag\torbit (orbit mode) / look around (fly mode)\n"
             "right drag, wheel\tpan, zoom (wheel over the panel scrolls it)\n"
             "W A S D, Q E\tmove forward/left/back/right, down/up (Shift: x5)\n"
             "C / R\torbit or fly camera / back to the scene camera\n"
             "K\trender at the scene's size (screenshots) / the window's\n"
             "Tab / O\tparameter panel / timings overlay\n"
             "Up, Down\tpick a parameter (or click it)\n"
             "Left, Right\tadjust it (Shift: x10); Space: toggle, next choice\n"
             "Enter / Del\ttype a value / back to its default\n"
             "+ / -\texposure +-0.5 EV (display and PNG)\n"
             "F5\treload shaders (errors shown, old shaders kept)\n"
             "P, F12\tscreenshot: EXR (linear) + PNG + window capture\n"
             "H, F1 / Esc\tthis help / close help, quit\n",
             cycle);
    return text;
}
