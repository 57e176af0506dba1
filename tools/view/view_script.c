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

// Runs one line; fills err (INPUT: bad line, RUNTIME: failed expectation).
static bool run_line(view *v, char *line, st_err *err) {
    char *tok[MAX_TOK];
    int n = 0;
    char copy[4096];
    snprintf(copy, sizeof copy, "%s", line);
    for (char *save = NULL, *t = strtok_r(copy, " \t\r\n", &save); t && n < MAX_TOK;
         t = strtok_r(NULL, " \t\r\n", &save))
        tok[n++] = t;
    if (!n || tok[0][0] == '#') return true;
    const char *cmd = tok[0];
    double a[6];
#define NEED(k, usage)                                                                             \
    do {                                                                                           \
        if (n != (k) + 1) return st_fail(err, ST_ERR_INPUT, "%s: usage: %s %s", cmd, cmd, usage);  \
    } while (0)
#define NUMS(k, usage)                                                                             \
    do {                                                                                           \
        NEED(k, usage);                                                                            \
        for (int _i = 0; _i < (k); _i++)                                                           \
            if (!num(tok[_i + 1], &a[_i]))                                                         \
                return st_fail(err, ST_ERR_INPUT, "%s: '%s' is not a number", cmd, tok[_i + 1]);   \
    } while (0)

    if (!strcmp(cmd, "frames")) {
        NUMS(1, "N");
        if (a[0] < 1 || a[0] > 1e6 || a[0] != floor(a[0]))
            return st_fail(err, ST_ERR_INPUT, "frames: N must be 1..1000000");
        for (long i = 0; i < (long)a[0] && !v->quit; i++)
            if (!view_frame(v, err)) return false;
        return true;
    }
    if (!strcmp(cmd, "key")) {
        if (n < 2)
            return st_fail(err, ST_ERR_INPUT,
                           "key: usage: key NAME... (e.g. key G, key F5, key Shift+Right)");
        for (int i = 1; i < n; i++) {
            int mods, k = view_key_from_name(tok[i], &mods);
            if (k < 0) return st_fail(err, ST_ERR_INPUT, "key: unknown key '%s'", tok[i]);
            // As in the window: a key whose action fails shows why and the
            // session goes on (expect-message can check the text).
            st_err kerr = {0};
            if (!view_key(v, k, mods, &kerr)) view_message(v, "%s", kerr.msg);
        }
        return true;
    }
    if (!strcmp(cmd, "type")) {
        for (const char *c = rest_after(line, 1); *c && *c != '\n' && *c != '\r'; c++)
            view_char(v, (unsigned char)*c);
        return true;
    }
    if (!strcmp(cmd, "set")) {
        char mod[ST_NAME_MAX], par[ST_NAME_MAX];
        NEED(2, "MODULE.PARAM VALUE");
        if (!split_param(tok[1], mod, par))
            return st_fail(err, ST_ERR_INPUT, "set: expected MODULE.PARAM, got '%s'", tok[1]);
        return view_set_param_text(v, mod, par, tok[2], err);
    }
    if (!strcmp(cmd, "enable") || !strcmp(cmd, "disable")) {
        NEED(1, "MODULE");
        return view_enable(v, tok[1], cmd[0] == 'e', err);
    }
    if (!strcmp(cmd, "exposure")) {
        NUMS(1, "EV");
        v->exposure = (float)a[0];
        return true;
    }
    if (!strcmp(cmd, "camera")) {
        NUMS(6, "PX PY PZ TX TY TZ");
        float p[3] = {(float)a[0], (float)a[1], (float)a[2]},
              t[3] = {(float)a[3], (float)a[4], (float)a[5]};
        view_set_camera(v, p, t);
        return true;
    }
    if (!strcmp(cmd, "orbit")) {
        NUMS(2, "DYAW DPITCH (degrees)");
        view_cam_rotate(&v->cam, (float)a[0], (float)a[1]);
        v->cam_dirty = true;
        return true;
    }
    if (!strcmp(cmd, "move")) {
        NUMS(3, "FWD RIGHT UP (metres)");
        view_cam_move(&v->cam, (float)a[0], (float)a[1], (float)a[2]);
        v->cam_dirty = true;
        return true;
    }
    if (!strcmp(cmd, "dolly")) {
        NUMS(1, "FACTOR");
        if (!(a[0] > 0)) return st_fail(err, ST_ERR_INPUT, "dolly: FACTOR must be > 0");
        view_cam_dolly(&v->cam, (float)a[0]);
        v->cam_dirty = true;
        return true;
    }
    if (!strcmp(cmd, "render-size")) {
        if (n == 2 && (!strcmp(tok[1], "scene") || !strcmp(tok[1], "window"))) {
            v->fixed_size = !strcmp(tok[1], "scene");
            if (v->fixed_size) v->render_w = v->scene->width, v->render_h = v->scene->height;
            return true;
        }
        NUMS(2, "W H, scene or window");
        if (a[0] < 1 || a[1] < 1 || a[0] > 16384 || a[1] > 16384)
            return st_fail(err, ST_ERR_INPUT, "render-size: 1..16384 each");
        v->fixed_size = true;
        v->render_w = (int)a[0], v->render_h = (int)a[1];
        return true;
    }
    if (!strcmp(cmd, "resize")) {
        NUMS(2, "W H");
        if (a[0] < 1 || a[1] < 1 || a[0] > 16384 || a[1] > 16384)
            return st_fail(err, ST_ERR_INPUT, "resize: 1..16384 each");
        glfwSetWindowSize(v->win, (int)a[0], (int)a[1]);
        // The window system answers asynchronously; wait (bounded) for it.
        int fw = 0, fh = 0;
        for (int i = 0; i < 200; i++) {
            glfwPollEvents();
            glfwGetFramebufferSize(v->win, &fw, &fh);
            if (fw == (int)a[0] && fh == (int)a[1]) break;
            glfwWaitEventsTimeout(0.005);
        }
        if (fw != (int)a[0] || fh != (int)a[1])
            return st_fail(err, ST_ERR_RUNTIME,
                           "resize: the window is %dx%d, not %dx%d (screen too small?)", fw, fh,
                           (int)a[0], (int)a[1]);
        return true;
    }
    if (!strcmp(cmd, "mouse")) {
        NUMS(2, "X Y (window pixels, from the top left)");
        view_mouse_move(v, a[0], a[1]);
        return true;
    }
    if (!strcmp(cmd, "button")) {
        NEED(2, "left|right|middle down|up");
        int b = !strcmp(tok[1], "left")     ? 0
                : !strcmp(tok[1], "right")  ? 1
                : !strcmp(tok[1], "middle") ? 2
                                            : -1;
        bool down = !strcmp(tok[2], "down");
        if (b < 0 || (!down && strcmp(tok[2], "up")))
            return st_fail(err, ST_ERR_INPUT, "button: usage: button left|right|middle down|up");
        view_mouse_button(v, b, down);
        return true;
    }
    if (!strcmp(cmd, "wheel")) {
        NUMS(1, "CLICKS (positive: away from the user)");
        view_mouse_wheel(v, a[0]);
        return true;
    }
    if (!strcmp(cmd, "reload")) {
        NEED(0, "");
        view_reload(v);
        return true;
    }
    if (!strcmp(cmd, "screenshot")) {
        NEED(1, "PATH[.exr|.png] (writes both)");
        return view_screenshot(v, tok[1], err);
    }
    if (!strcmp(cmd, "capture")) {
        NEED(1, "PATH.png (draws one frame)");
        snprintf(v->capture_path, sizeof v->capture_path, "%s", tok[1]);
        v->want_capture = true;
        return view_frame(v, err);
    }
    if (!strcmp(cmd, "stats")) {
        NEED(1, "PATH.json");
        return view_write_stats(v, tok[1], err);
    }
    // `sh` runs a shell command on purpose: a script is code, written by the
    // user like a shell script (docs/security.md). Nothing else in strahl
    // starts a shell.
    if (!strcmp(cmd, "sh")) {
        const char *c = rest_after(line, 1);
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
    if (!strcmp(cmd, "expect-error")) {
        const char *want = rest_after(line, 1);
        char w[1024];
        snprintf(w, sizeof w, "%s", want);
        w[strcspn(w, "\r\n")] = 0;
        if (!v->error[0]) return st_fail(err, ST_ERR_RUNTIME, "expect-error: no error is shown");
        if (w[0] && !strstr(v->error, w))
            return st_fail(err, ST_ERR_RUNTIME,
                           "expect-error: the error shown does not contain '%s': %s", w, v->error);
        printf("strahl view: error shown as expected: %s\n", v->error);
        return true;
    }
    if (!strcmp(cmd, "expect-ok")) {
        NEED(0, "");
        if (v->error[0])
            return st_fail(err, ST_ERR_RUNTIME, "expect-ok: an error is shown: %s", v->error);
        return true;
    }
    if (!strcmp(cmd, "expect-message")) {
        char w[1024];
        snprintf(w, sizeof w, "%s", rest_after(line, 1));
        w[strcspn(w, "\r\n")] = 0;
        if (!strstr(v->message, w))
            return st_fail(err, ST_ERR_RUNTIME, "expect-message: '%s' not in the last message: %s",
                           w, v->message);
        return true;
    }
    if (!strcmp(cmd, "expect-param")) {
        char mod[ST_NAME_MAX], par[ST_NAME_MAX];
        NEED(2, "MODULE.PARAM VALUE");
        if (!split_param(tok[1], mod, par) || !num(tok[2], &a[0]))
            return st_fail(err, ST_ERR_INPUT,
                           "expect-param: usage: expect-param MODULE.PARAM NUMBER");
        double got;
        if (!st_world_get_param(v->world, mod, par, &got))
            return st_fail(err, ST_ERR_RUNTIME, "expect-param: %s.%s is not loaded", mod, par);
        if (fabs(got - a[0]) > 1e-9 * (1 + fabs(a[0])))
            return st_fail(err, ST_ERR_RUNTIME, "expect-param: %s.%s is %.17g, expected %.17g", mod,
                           par, got, a[0]);
        return true;
    }
    if (!strcmp(cmd, "expect-module")) {
        NEED(2, "MODULE on|off");
        bool want = !strcmp(tok[2], "on");
        if (!want && strcmp(tok[2], "off"))
            return st_fail(err, ST_ERR_INPUT, "expect-module: on or off, not '%s'", tok[2]);
        if (st_world_has_module(v->world, tok[1]) != want)
            return st_fail(err, ST_ERR_RUNTIME, "expect-module: %s is %s", tok[1],
                           want ? "off" : "on");
        return true;
    }
    if (!strcmp(cmd, "quit")) {
        NEED(0, "");
        v->quit = true;
        return true;
    }
    return st_fail(err, ST_ERR_INPUT, "unknown command '%s'", cmd);
#undef NEED
#undef NUMS
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
