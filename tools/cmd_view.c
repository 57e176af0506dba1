// strahl view: an interactive window on a scene, with module switching, a
// parameter panel built from the plugin descriptors, per-pass GPU timings,
// screenshots, shader hot reload, and a scripted mode (--script) that drives
// the same frame and action code for tests and demos. See tools/view/.
#define _GNU_SOURCE
#include "cmd_common.h"
#include "st_cmd.h"
#include "st_file.h"
#include "view/view.h"
#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SETS 64

static const char help_text[] =
    "usage: strahl view SCENE.json [options]\n"
    "An interactive window on a scene (press H in it for the keys).\n"
    "  --script FILE             run the commands in FILE, then exit (default: interactive)\n"
    "  --size WxH                render at this size, scaled into the window; screenshots\n"
    "                            have it (default: render at the window's size; key K\n"
    "                            switches to the scene's image size)\n"
    "  --window WxH              window size (default: the scene's aspect at 3/4 of the\n"
    "                            screen, at least 960x540 where it fits; with --script:\n"
    "                            --size or the scene's image size)\n"
    "  --set MODULE.PARAM=VALUE  change a module parameter (repeatable)\n"
    "  --exposure EV             display exposure in stops, -64..64 (default 0)\n"
    "  --filter box|point        pixel filter (default: the scene's image.filter, box): box\n"
    "                            accumulates jittered frames while nothing changes\n"
    "  --ui-scale S              overlay text scale, 0.5..8 (default 1)\n"
    "  --shots DIR               screenshot folder (default .)\n"
    "  --hide-panel              start with the parameter panel hidden (default shown)\n"
    "  --allow-outside-assets    let glTF buffer/image URIs leave the glTF file's folder\n"
    "                            (default: refused)\n" ST_CMD_SCENE_HELP
    "  -h, --help                this text\n"
    "script (--script FILE): one command per line, # starts a comment; exit 0 when every\n"
    "line ran, 1 for a failed expect-* or a runtime error, 2 for a bad line (docs/viewer.md):\n"
    "  frames N                      render N frames\n"
    "  key NAME...                   press keys (G, 1, F5, Tab, Enter, Up, Shift+Right, ...)\n"
    "  type TEXT                     characters into the text field (after key Enter)\n"
    "  mouse X Y | button left|right|middle down|up | wheel CLICKS   mouse input\n"
    "  set MODULE.PARAM VALUE        number, true/false or choice name (range-checked)\n"
    "  enable MODULE | disable MODULE   switch a module (with its requirements)\n"
    "  camera PX PY PZ TX TY TZ      camera position and target\n"
    "  orbit DYAW DPITCH | move FWD RIGHT UP | dolly FACTOR   move the camera\n"
    "  resize W H                    resize the window (and the render)\n"
    "  render-size W H | render-size scene | render-size window   what the world renders at\n"
    "  exposure EV                   display and PNG exposure\n"
    "  reload                        hot reload of the shaders (F5)\n"
    "  screenshot PATH               PATH.exr and PATH.png of the last frame\n"
    "  capture PATH.png              the window with the overlay\n"
    "  stats PATH.json               the last frame's passes, camera, modules, widgets\n"
    "  sh COMMAND                    run a shell command; non-zero exit fails\n"
    "  expect-error [TEXT] | expect-ok | expect-message TEXT   the shown error or message\n"
    "  expect-param MODULE.PARAM VALUE | expect-module MODULE on|off   state checks\n"
    "  quit                          stop here\n"
    "example:\n"
    "  strahl view scenes/godrays_colonnade.json --set toth.samples=64\n";

// A usable window for an interactive session: the scene's aspect, as large as
// fits in 3/4 of the screen (at least 960x540 where the screen allows), never
// more than 9/10 of it.
static void usable_window(int sw, int sh, int *ww, int *wh) {
    int mw = 1920, mh = 1080;
    if (glfwInit()) { // st_context_create_window calls it again; that is allowed
        GLFWmonitor *mon = glfwGetPrimaryMonitor();
        const GLFWvidmode *mode = mon ? glfwGetVideoMode(mon) : NULL;
        if (mode && mode->width > 0 && mode->height > 0) mw = mode->width, mh = mode->height;
    }
    double bw = fmin(fmax(960.0, 0.75 * mw), 0.9 * mw), bh = fmin(fmax(540.0, 0.75 * mh), 0.9 * mh);
    double s = fmin(bw / sw, bh / sh);
    *ww = (int)fmax(1.0, sw * s + 0.5);
    *wh = (int)fmax(1.0, sh * s + 0.5);
}

typedef struct view_args {
    const char *scene_path, *script, *shots;
    char *sets[MAX_SETS];
    int num_sets, width, height, win_w, win_h;
    double exposure, ui_scale;
    st_pixel_filter filter;
    bool filter_given, hide_panel;
} view_args;

// Options with a checked value; *known says whether `a` is one of them.
static bool parse_value(void *ctx, const char *a, const char *v, bool *known, st_err *err) {
    view_args *o = ctx;
    char *e;
    *known = true;
    if (!strcmp(a, "--size")) {
        if (!st_parse_size(v, &o->width, &o->height))
            return st_fail(err, ST_ERR_INPUT, "--size %s: expected WxH, 1..16384 each", v);
    } else if (!strcmp(a, "--window")) {
        if (!st_parse_size(v, &o->win_w, &o->win_h))
            return st_fail(err, ST_ERR_INPUT, "--window %s: expected WxH, 1..16384 each", v);
    } else if (!strcmp(a, "--filter")) {
        if (!st_filter_parse(v, &o->filter))
            return st_fail(err, ST_ERR_INPUT, "--filter %s: expected box or point", v);
        o->filter_given = true;
    } else if (!strcmp(a, "--exposure")) {
        o->exposure = strtod(v, &e);
        if (*e || !isfinite(o->exposure) || fabs(o->exposure) > 64)
            return st_fail(err, ST_ERR_INPUT,
                           "--exposure %s: expected a number of stops in [-64, 64]", v);
    } else if (!strcmp(a, "--ui-scale")) {
        o->ui_scale = strtod(v, &e);
        if (*e || !(o->ui_scale >= 0.5 && o->ui_scale <= 8))
            return st_fail(err, ST_ERR_INPUT, "--ui-scale %s: expected 0.5..8", v);
    } else if (!strcmp(a, "--script")) {
        o->script = v;
    } else if (!strcmp(a, "--shots")) {
        o->shots = v;
    } else if (!strcmp(a, "--set")) {
        if (o->num_sets == MAX_SETS) return st_fail(err, ST_ERR_INPUT, "too many --set (max 64)");
        o->sets[o->num_sets++] = (char *)v;
    } else {
        *known = false;
    }
    return true;
}

static bool view_flag(void *ctx, const char *a) {
    view_args *o = ctx;
    if (strcmp(a, "--hide-panel")) return false;
    o->hide_panel = true;
    return true;
}

// Fills o from argv; *help: -h was given (the text is printed).
static bool parse_args(view_args *o, int argc, char **argv, bool *help, st_err *err) {
    static const st_argv_spec spec = {
        help_text,
        " (usage: strahl view SCENE.json [--script FILE] [--size WxH] [--window WxH] [--set "
        "MODULE.PARAM=VALUE]... [--exposure EV] [--ui-scale S] [--shots DIR] [--hide-panel])",
        parse_value, view_flag};
    if (!st_cmd_walk_args(&spec, o, argc, argv, &o->scene_path, help, err)) return false;
    if (*help) return true;
    if (!o->scene_path)
        return st_fail(err, ST_ERR_INPUT,
                       "usage: strahl view SCENE.json [--script FILE] [options]");
    return true;
}

// The window, the world and the viewer's state for the loaded scene.
static bool open_view(view *v, const view_args *o, st_scene *scene, st_err *err) {
    v->script = o->script != NULL;
    // Scripts (tests) keep a window of the render size, so window pixels and
    // screenshots correspond; an interactive session opens a usable window.
    int win_w = o->win_w, win_h = o->win_h;
    if (!win_w) {
        if (v->script)
            win_w = scene->width, win_h = scene->height;
        else
            usable_window(scene->width, scene->height, &win_w, &win_h);
    }
    v->render_w = scene->width, v->render_h = scene->height;
    // --size fixes the render size in an interactive window (screenshots at
    // that size, like strahl render); in a script the window has that size.
    v->fixed_size = o->width > 0 && !v->script;
    v->ctx = st_context_create_window(win_w, win_h, "strahl view", v->script ? 0 : 1, err);
    if (!v->ctx) return false;
    v->win = st_context_window(v->ctx);
    int fw, fh;
    glfwGetFramebufferSize(v->win, &fw, &fh);
    st_world_opts opts = {.width = v->fixed_size ? v->render_w : fw,
                          .height = v->fixed_size ? v->render_h : fh,
                          .timing = true,
                          .filter = o->filter_given ? o->filter : scene->filter};
    v->scene = scene;
    v->scene_path = o->scene_path;
    v->script_path = o->script;
    v->world = st_world_create(scene, &opts, err);
    if (!v->world) return false;
    v->gl.scale = (float)o->ui_scale;
    if (!view_gl_init(&v->gl, err)) return false;
    view_cam_init(&v->cam, &scene->camera);
    v->cam_home = v->cam;
    v->show_panel = !o->hide_panel;
    v->show_stats = true;
    v->exposure = (float)o->exposure;
    v->drag_param = -1;
    v->sel_param = -1;
    snprintf(v->shot_dir, sizeof v->shot_dir, "%s", o->shots);
    view_refresh_modules(v);
    view_install_callbacks(v);
    printf("strahl view: %s, window %dx%d, rendering %dx%d on %s; %d module(s) installed; press H "
           "for help\n",
           o->scene_path, fw, fh, opts.width, opts.height, st_context_renderer(), v->num_mods);
    fflush(stdout);
    return true;
}

int st_cmd_view(int argc, char **argv) {
    view_args o = {.shots = ".", .ui_scale = 1, .filter = ST_FILTER_BOX};
    st_err err = {0};
    bool help;
    if (!parse_args(&o, argc, argv, &help, &err)) return st_report("view", &err);
    if (help) return ST_EXIT_OK;
    st_scene scene = {0};
    // The script is read (a regular file within the cap) before any window opens.
    FILE *script_f = o.script ? st_fopen_input(o.script, ST_CAP_TEXT, "viewer script", &err) : NULL;
    if (o.script && !script_f) return st_report("view", &err);
    if (!st_load_scene_with(o.scene_path, o.sets, o.num_sets, o.width, o.height, &scene, &err)) {
        if (script_f) fclose(script_f);
        return st_report("view", &err);
    }
    int rc = ST_EXIT_OK;
    view *v = calloc(1, sizeof *v);
    if (!v) {
        if (script_f) fclose(script_f);
        st_scene_free(&scene);
        return st_fail(&err, ST_ERR_RUNTIME, "out of memory"), st_report("view", &err);
    }
    bool ok = open_view(v, &o, &scene, &err);
    if (ok && o.script) {
        rc = view_run_script(v, o.script, script_f);
        script_f = NULL; // closed by view_run_script
    } else {
        while (ok && !v->quit)
            ok = view_frame(v, &err);
    }
    if (!ok) rc = st_report("view", &err);
    if (script_f) fclose(script_f);
    if (v->world) st_world_destroy(v->world);
    if (v->ctx) view_gl_free(&v->gl);
    st_context_destroy(v->ctx);
    free(v->prev_totals);
    free(v);
    st_scene_free(&scene);
    return rc;
}
