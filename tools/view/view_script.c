// Scripted strahl view sessions (tests, demos): one command per line, run
// between frames through the same actions as the keyboard and the panel.
//
//   # comment                    frames N              key NAME...
//   (key: the keyboard's action; a failing one is shown as the message and
//   the script goes on, as in the window; the other commands stop it)
//   type TEXT                    set MODULE.PARAM VALUE
//   enable MODULE                disable MODULE        exposure EV
//   camera PX PY PZ TX TY TZ     orbit DYAW DPITCH     move FWD RIGHT UP
//   dolly FACTOR                 resize W H            reload
//   screenshot PATH              capture PATH.png      stats PATH.json
//   sh COMMAND                   expect-error [TEXT]   expect-ok
//   expect-message TEXT          expect-param MODULE.PARAM VALUE
//   expect-module MODULE on|off  mouse X Y             button left|right|middle down|up
//   wheel CLICKS                 quit
//   render-size W H | scene | window   (what the world renders at; see key K)
// (mouse input acts in the next frame, as events from the window do; the
// panel's control rectangles are in the `stats` output under "widgets")
//
// Exit codes: 0 ok, 1 a failed expectation or a runtime error, 2 a bad line
// (unknown command, bad number, unknown module or parameter, out of range).
#define _GNU_SOURCE
#include "view.h"
#include <GLFW/glfw3.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#define MAX_TOK 8

static bool num(const char *s, double *out) {
    char *e;
    errno = 0;
    double d = strtod(s, &e);
    if (e == s || *e || errno || !isfinite(d)) return false;
    *out = d;
    return true;
}

static const char *rest_after(const char *line, int ntok) {
    const char *p = line;
    for (int i = 0; i < ntok; i++) {
        while (isspace((unsigned char)*p))
            p++;
        while (*p && !isspace((unsigned char)*p))
            p++;
    }
    while (isspace((unsigned char)*p))
        p++;
    return p;
}

// Splits "module.param".
static bool split_param(const char *s, char *mod, char *par) {
    const char *dot = strchr(s, '.');
    if (!dot || dot == s || !dot[1] || dot - s >= ST_NAME_MAX || strlen(dot + 1) >= ST_NAME_MAX)
        return false;
    snprintf(mod, ST_NAME_MAX, "%.*s", (int)(dot - s), s);
    snprintf(par, ST_NAME_MAX, "%s", dot + 1);
    return true;
}

// One script line split into words; a[] holds the numbers nums() read.
typedef struct line {
    const char *text; // the whole line (for commands that take the rest of it)
    char *tok[MAX_TOK];
    int n;
    const char *cmd;
    double a[6];
} line;

// Exactly k arguments.
static bool need(const line *l, int k, const char *usage, st_err *err) {
    if (l->n != k + 1) return st_fail(err, ST_ERR_INPUT, "%s: usage: %s %s", l->cmd, l->cmd, usage);
    return true;
}

// Exactly k numeric arguments, into l->a.
static bool nums(line *l, int k, const char *usage, st_err *err) {
    if (!need(l, k, usage, err)) return false;
    for (int i = 0; i < k; i++)
        if (!num(l->tok[i + 1], &l->a[i]))
            return st_fail(err, ST_ERR_INPUT, "%s: '%s' is not a number", l->cmd, l->tok[i + 1]);
    return true;
}

// The rest of the line after the command, without its line end.
static void rest_text(const line *l, char *out, size_t n) {
    snprintf(out, n, "%s", rest_after(l->text, 1));
    out[strcspn(out, "\r\n")] = 0;
}

// ---- the commands (each: the line's words after the command) ---------------

static bool c_frames(view *v, line *l, st_err *err) {
    if (!nums(l, 1, "N", err)) return false;
    if (l->a[0] < 1 || l->a[0] > 1e6 || l->a[0] != floor(l->a[0]))
        return st_fail(err, ST_ERR_INPUT, "frames: N must be 1..1000000");
    for (long i = 0; i < (long)l->a[0] && !v->quit; i++)
        if (!view_frame(v, err)) return false;
    return true;
}

static bool c_key(view *v, line *l, st_err *err) {
    if (l->n < 2)
        return st_fail(err, ST_ERR_INPUT,
                       "key: usage: key NAME... (e.g. key G, key F5, key Shift+Right)");
    for (int i = 1; i < l->n; i++) {
        int mods, k = view_key_from_name(l->tok[i], &mods);
        if (k < 0) return st_fail(err, ST_ERR_INPUT, "key: unknown key '%s'", l->tok[i]);
        // As in the window: a key whose action fails shows why and the
        // session goes on (expect-message can check the text).
        st_err kerr = {0};
        if (!view_key(v, k, mods, &kerr)) view_message(v, "%s", kerr.msg);
    }
    return true;
}

static bool c_type(view *v, line *l, st_err *err) {
    for (const char *c = rest_after(l->text, 1); *c && *c != '\n' && *c != '\r'; c++)
        view_char(v, (unsigned char)*c);
    return true;
}

static bool c_set(view *v, line *l, st_err *err) {
    char mod[ST_NAME_MAX], par[ST_NAME_MAX];
    if (!need(l, 2, "MODULE.PARAM VALUE", err)) return false;
    if (!split_param(l->tok[1], mod, par))
        return st_fail(err, ST_ERR_INPUT, "set: expected MODULE.PARAM, got '%s'", l->tok[1]);
    return view_set_param_text(v, mod, par, l->tok[2], err);
}

static bool c_enable(view *v, line *l, st_err *err) {
    return need(l, 1, "MODULE", err) && view_enable(v, l->tok[1], l->cmd[0] == 'e', err);
}

static bool c_exposure(view *v, line *l, st_err *err) {
    if (!nums(l, 1, "EV", err)) return false;
    v->exposure = (float)l->a[0];
    return true;
}

// The camera a command left: finite, with a view direction, as the scene
// file requires; otherwise `before` is restored and the line refused.
static bool camera_ok(view *v, const view_cam *before, const line *l, st_err *err) {
    const view_cam *c = &v->cam;
    double dd = 0;
    bool finite = true;
    for (int k = 0; k < 3; k++) {
        double d = (double)c->target[k] - c->pos[k];
        dd += d * d;
        finite = finite && isfinite(c->pos[k]) && isfinite(c->target[k]) && isfinite(c->up[k]);
    }
    const char *why = !finite     ? "leaves the camera at a non-finite position or target"
                      : !(dd > 0) ? "puts the target at the position (no view direction)"
                                  : NULL;
    if (!why) {
        v->cam_dirty = true;
        return true;
    }
    v->cam = *before;
    char words[512] = "";
    for (int i = 0, n = 0; i < l->n && n < (int)sizeof words; i++)
        n += snprintf(words + n, sizeof words - (size_t)n, "%s%s", i ? " " : "", l->tok[i]);
    return st_fail(err, ST_ERR_INPUT, "%s: %s", words, why);
}

// A number that must survive the conversion to float (the camera's type).
static bool float_range(const line *l, int n, st_err *err) {
    for (int i = 0; i < n; i++)
        if (!(fabs(l->a[i]) <= 3.4e38))
            return st_fail(err, ST_ERR_INPUT, "%s: '%s' is out of range for a float", l->cmd,
                           l->tok[i + 1]);
    return true;
}

static bool c_camera(view *v, line *l, st_err *err) {
    if (!nums(l, 6, "PX PY PZ TX TY TZ", err) || !float_range(l, 6, err)) return false;
    const double *a = l->a;
    float p[3] = {(float)a[0], (float)a[1], (float)a[2]},
          t[3] = {(float)a[3], (float)a[4], (float)a[5]};
    view_cam before = v->cam;
    view_set_camera(v, p, t);
    return camera_ok(v, &before, l, err);
}

static bool c_orbit(view *v, line *l, st_err *err) {
    if (!nums(l, 2, "DYAW DPITCH (degrees)", err) || !float_range(l, 2, err)) return false;
    view_cam before = v->cam;
    view_cam_rotate(&v->cam, (float)l->a[0], (float)l->a[1]);
    return camera_ok(v, &before, l, err);
}

static bool c_move(view *v, line *l, st_err *err) {
    if (!nums(l, 3, "FWD RIGHT UP (metres)", err) || !float_range(l, 3, err)) return false;
    view_cam before = v->cam;
    view_cam_move(&v->cam, (float)l->a[0], (float)l->a[1], (float)l->a[2]);
    return camera_ok(v, &before, l, err);
}

static bool c_dolly(view *v, line *l, st_err *err) {
    if (!nums(l, 1, "FACTOR", err) || !float_range(l, 1, err)) return false;
    if (!(l->a[0] > 0)) return st_fail(err, ST_ERR_INPUT, "dolly: FACTOR must be > 0");
    view_cam before = v->cam;
    view_cam_dolly(&v->cam, (float)l->a[0]);
    return camera_ok(v, &before, l, err);
}

static bool c_render_size(view *v, line *l, st_err *err) {
    if (l->n == 2 && (!strcmp(l->tok[1], "scene") || !strcmp(l->tok[1], "window"))) {
        v->fixed_size = !strcmp(l->tok[1], "scene");
        if (v->fixed_size) v->render_w = v->scene->width, v->render_h = v->scene->height;
        return true;
    }
    if (!nums(l, 2, "W H, scene or window", err)) return false;
    if (l->a[0] < 1 || l->a[1] < 1 || l->a[0] > 16384 || l->a[1] > 16384)
        return st_fail(err, ST_ERR_INPUT, "render-size: 1..16384 each");
    v->fixed_size = true;
    v->render_w = (int)l->a[0], v->render_h = (int)l->a[1];
    return true;
}

static bool c_resize(view *v, line *l, st_err *err) {
    if (!nums(l, 2, "W H", err)) return false;
    if (l->a[0] < 1 || l->a[1] < 1 || l->a[0] > 16384 || l->a[1] > 16384)
        return st_fail(err, ST_ERR_INPUT, "resize: 1..16384 each");
    int w = (int)l->a[0], h = (int)l->a[1];
    glfwSetWindowSize(v->win, w, h);
    // The window system answers asynchronously; wait (bounded) for it.
    int fw = 0, fh = 0;
    for (int i = 0; i < 200; i++) {
        glfwPollEvents();
        glfwGetFramebufferSize(v->win, &fw, &fh);
        if (fw == w && fh == h) break;
        glfwWaitEventsTimeout(0.005);
    }
    if (fw != w || fh != h)
        return st_fail(err, ST_ERR_RUNTIME,
                       "resize: the window is %dx%d, not %dx%d (screen too small?)", fw, fh, w, h);
    return true;
}

static bool c_mouse(view *v, line *l, st_err *err) {
    if (!nums(l, 2, "X Y (window pixels, from the top left)", err)) return false;
    view_mouse_move(v, l->a[0], l->a[1]);
    return true;
}

static bool c_button(view *v, line *l, st_err *err) {
    if (!need(l, 2, "left|right|middle down|up", err)) return false;
    const char *name = l->tok[1];
    int b = !strcmp(name, "left")     ? 0
            : !strcmp(name, "right")  ? 1
            : !strcmp(name, "middle") ? 2
                                      : -1;
    bool down = !strcmp(l->tok[2], "down");
    if (b < 0 || (!down && strcmp(l->tok[2], "up")))
        return st_fail(err, ST_ERR_INPUT, "button: usage: button left|right|middle down|up");
    view_mouse_button(v, b, down);
    return true;
}

static bool c_wheel(view *v, line *l, st_err *err) {
    if (!nums(l, 1, "CLICKS (positive: away from the user)", err)) return false;
    view_mouse_wheel(v, l->a[0]);
    return true;
}

static bool c_reload(view *v, line *l, st_err *err) {
    if (!need(l, 0, "", err)) return false;
    view_reload(v);
    return true;
}

static bool c_screenshot(view *v, line *l, st_err *err) {
    return need(l, 1, "PATH[.exr|.png] (writes both)", err) && view_screenshot(v, l->tok[1], err);
}

static bool c_capture(view *v, line *l, st_err *err) {
    static const char *const png_ext[] = {"png", NULL};
    if (!need(l, 1, "PATH.png (draws one frame)", err) ||
        !view_check_output(v, "capture", l->tok[1], png_ext, err))
        return false;
    snprintf(v->capture_path, sizeof v->capture_path, "%s", l->tok[1]);
    v->want_capture = true;
    return view_frame(v, err);
}

static bool c_stats(view *v, line *l, st_err *err) {
    return need(l, 1, "PATH.json", err) && view_write_stats(v, l->tok[1], err);
}

// `sh` runs a shell command on purpose: a script is code, written by the
// user like a shell script (docs/security.md). Nothing else in strahl
// starts a shell.
static bool c_sh(view *v, line *l, st_err *err) {
    const char *c = rest_after(l->text, 1);
    if (!*c) return st_fail(err, ST_ERR_INPUT, "sh: usage: sh COMMAND");
    fflush(stdout);
    int rc = system(c);
    if (rc == -1 || !WIFEXITED(rc) || WEXITSTATUS(rc))
        return st_fail(err, ST_ERR_RUNTIME, "sh: '%s' failed (status %d)", c,
                       rc == -1        ? -1
                       : WIFEXITED(rc) ? WEXITSTATUS(rc)
                                       : 128 + WTERMSIG(rc));
    return true;
}

static bool c_expect_error(view *v, line *l, st_err *err) {
    char w[1024];
    rest_text(l, w, sizeof w);
    if (!v->error[0]) return st_fail(err, ST_ERR_RUNTIME, "expect-error: no error is shown");
    if (w[0] && !strstr(v->error, w))
        return st_fail(err, ST_ERR_RUNTIME,
                       "expect-error: the error shown does not contain '%s': %s", w, v->error);
    printf("strahl view: error shown as expected: %s\n", v->error);
    return true;
}

static bool c_expect_ok(view *v, line *l, st_err *err) {
    if (!need(l, 0, "", err)) return false;
    if (v->error[0])
        return st_fail(err, ST_ERR_RUNTIME, "expect-ok: an error is shown: %s", v->error);
    return true;
}

static bool c_expect_message(view *v, line *l, st_err *err) {
    char w[1024];
    rest_text(l, w, sizeof w);
    if (!strstr(v->message, w))
        return st_fail(err, ST_ERR_RUNTIME, "expect-message: '%s' not in the last message: %s", w,
                       v->message);
    return true;
}

static bool c_expect_param(view *v, line *l, st_err *err) {
    char mod[ST_NAME_MAX], par[ST_NAME_MAX];
    if (!need(l, 2, "MODULE.PARAM VALUE", err)) return false;
    double want, got;
    if (!split_param(l->tok[1], mod, par) || !num(l->tok[2], &want))
        return st_fail(err, ST_ERR_INPUT, "expect-param: usage: expect-param MODULE.PARAM NUMBER");
    if (!st_world_get_param(v->world, mod, par, &got))
        return st_fail(err, ST_ERR_RUNTIME, "expect-param: %s.%s is not loaded", mod, par);
    if (fabs(got - want) > 1e-9 * (1 + fabs(want)))
        return st_fail(err, ST_ERR_RUNTIME, "expect-param: %s.%s is %.17g, expected %.17g", mod,
                       par, got, want);
    return true;
}

static bool c_expect_module(view *v, line *l, st_err *err) {
    if (!need(l, 2, "MODULE on|off", err)) return false;
    bool want = !strcmp(l->tok[2], "on");
    if (!want && strcmp(l->tok[2], "off"))
        return st_fail(err, ST_ERR_INPUT, "expect-module: on or off, not '%s'", l->tok[2]);
    if (st_world_has_module(v->world, l->tok[1]) != want)
        return st_fail(err, ST_ERR_RUNTIME, "expect-module: %s is %s", l->tok[1],
                       want ? "off" : "on");
    return true;
}

static bool c_quit(view *v, line *l, st_err *err) {
    if (!need(l, 0, "", err)) return false;
    v->quit = true;
    return true;
}

static const struct {
    const char *name;
    bool (*run)(view *v, line *l, st_err *err);
} commands[] = {
    {"frames", c_frames},
    {"key", c_key},
    {"type", c_type},
    {"set", c_set},
    {"enable", c_enable},
    {"disable", c_enable},
    {"exposure", c_exposure},
    {"camera", c_camera},
    {"orbit", c_orbit},
    {"move", c_move},
    {"dolly", c_dolly},
    {"render-size", c_render_size},
    {"resize", c_resize},
    {"mouse", c_mouse},
    {"button", c_button},
    {"wheel", c_wheel},
    {"reload", c_reload},
    {"screenshot", c_screenshot},
    {"capture", c_capture},
    {"stats", c_stats},
    {"sh", c_sh},
    {"expect-error", c_expect_error},
    {"expect-ok", c_expect_ok},
    {"expect-message", c_expect_message},
    {"expect-param", c_expect_param},
    {"expect-module", c_expect_module},
    {"quit", c_quit},
};

// Runs one line; fills err (INPUT: bad line, RUNTIME: failed expectation).
static bool run_line(view *v, char *text, st_err *err) {
    line l = {.text = text};
    char copy[4096];
    snprintf(copy, sizeof copy, "%s", text);
    for (char *save = NULL, *t = strtok_r(copy, " \t\r\n", &save); t && l.n < MAX_TOK;
         t = strtok_r(NULL, " \t\r\n", &save))
        l.tok[l.n++] = t;
    if (!l.n || l.tok[0][0] == '#') return true;
    l.cmd = l.tok[0];
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(l.cmd, commands[i].name)) return commands[i].run(v, &l, err);
    return st_fail(err, ST_ERR_INPUT, "unknown command '%s'", l.cmd);
}

int view_run_script(view *v, const char *path, FILE *f) {
    char line[4096];
    int lineno = 0, rc = ST_EXIT_OK;
    while (!v->quit && fgets(line, sizeof line, f)) {
        lineno++;
        st_err err = {0};
        if (!run_line(v, line, &err)) {
            fprintf(stderr, "strahl view: %s:%d: %s\n", path, lineno, err.msg);
            rc = st_err_exit_code(&err);
            break;
        }
    }
    fclose(f);
    return rc;
}
