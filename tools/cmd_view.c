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
    "                            (default: refused)\n"
    "  -h, --help                this text\n"
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

static int usage_error(const char *fmt, const char *arg) {
    st_err err = {0};
    st_fail(&err, ST_ERR_INPUT, fmt, arg);
    return st_report("view", &err);
}

int st_cmd_view(int argc, char **argv) {
    const char *scene_path = NULL, *script = NULL, *shots = ".";
    char *sets[MAX_SETS];
    int num_sets = 0, width = 0, height = 0, win_w = 0, win_h = 0;
    double exposure = 0, ui_scale = 1;
    st_pixel_filter filter = ST_FILTER_BOX;
    bool filter_given = false;
    bool hide_panel = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool has_next = i + 1 < argc;
        char *e;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(help_text, stdout);
            return ST_EXIT_OK;
        } else if (!strcmp(a, "--script") && has_next) {
            script = argv[++i];
        } else if (!strcmp(a, "--set") && has_next) {
            if (num_sets == MAX_SETS) return usage_error("too many --set (max 64)%s", "");
            sets[num_sets++] = argv[++i];
        } else if (!strcmp(a, "--size") && has_next) {
            if (!st_parse_size(argv[++i], &width, &height))
                return usage_error("--size %s: expected WxH, 1..16384 each", argv[i]);
        } else if (!strcmp(a, "--window") && has_next) {
            if (!st_parse_size(argv[++i], &win_w, &win_h))
                return usage_error("--window %s: expected WxH, 1..16384 each", argv[i]);
        } else if (!strcmp(a, "--filter") && has_next) {
            if (!st_filter_parse(argv[++i], &filter))
                return usage_error("--filter %s: expected box or point", argv[i]);
            filter_given = true;
        } else if (!strcmp(a, "--exposure") && has_next) {
            exposure = strtod(argv[++i], &e);
            if (*e || !isfinite(exposure) || fabs(exposure) > 64)
                return usage_error("--exposure %s: expected a number of stops in [-64, 64]",
                                   argv[i]);
        } else if (!strcmp(a, "--ui-scale") && has_next) {
            ui_scale = strtod(argv[++i], &e);
            if (*e || !(ui_scale >= 0.5 && ui_scale <= 8))
                return usage_error("--ui-scale %s: expected 0.5..8", argv[i]);
        } else if (!strcmp(a, "--shots") && has_next) {
            shots = argv[++i];
        } else if (!strcmp(a, "--hide-panel")) {
            hide_panel = true;
        } else if (st_cmd_scene_option(a)) {
        } else if (a[0] == '-' || scene_path) {
            return usage_error("unexpected argument '%s' (usage: strahl view SCENE.json [--script "
                               "FILE] [--size WxH] "
                               "[--window WxH] [--set MODULE.PARAM=VALUE]... [--exposure EV] "
                               "[--ui-scale S] [--shots DIR] [--hide-panel])",
                               a);
        } else {
            scene_path = a;
        }
    }
    if (!scene_path)
        return usage_error("usage: strahl view SCENE.json [--script FILE] [options]%s", "");

    st_err err = {0};
    st_scene scene = {0};
    // The script is read (a regular file within the cap) before any window opens.
    FILE *script_f = script ? st_fopen_input(script, ST_CAP_TEXT, "viewer script", &err) : NULL;
    if (script && !script_f) return st_report("view", &err);
    if (!st_load_scene_with(scene_path, sets, num_sets, width, height, &scene, &err)) {
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
    v->script = script != NULL;
    // Scripts (tests) keep a window of the render size, so window pixels and
    // screenshots correspond; an interactive session opens a usable window.
    if (!win_w) {
        if (v->script)
            win_w = scene.width, win_h = scene.height;
        else
            usable_window(scene.width, scene.height, &win_w, &win_h);
    }
    v->render_w = scene.width, v->render_h = scene.height;
    // --size fixes the render size in an interactive window (screenshots at
    // that size, like strahl render); in a script the window has that size.
    v->fixed_size = width > 0 && !v->script;
    v->ctx = st_context_create_window(win_w, win_h, "strahl view", v->script ? 0 : 1, &err);
    if (!v->ctx) goto fail;
    v->win = st_context_window(v->ctx);
    int fw, fh;
    glfwGetFramebufferSize(v->win, &fw, &fh);
    st_world_opts opts = {.width = v->fixed_size ? v->render_w : fw,
                          .height = v->fixed_size ? v->render_h : fh,
                          .timing = true,
                          .filter = filter_given ? filter : scene.filter};
    v->scene = &scene;
    v->world = st_world_create(&scene, &opts, &err);
    if (!v->world) goto fail;
    v->gl.scale = (float)ui_scale;
    if (!view_gl_init(&v->gl, &err)) goto fail;
    view_cam_init(&v->cam, &scene.camera);
    v->cam_home = v->cam;
    v->show_panel = !hide_panel;
    v->show_stats = true;
    v->exposure = (float)exposure;
    v->drag_param = -1;
    v->sel_param = -1;
    snprintf(v->shot_dir, sizeof v->shot_dir, "%s", shots);
    view_refresh_modules(v);
    view_install_callbacks(v);
    printf("strahl view: %s, window %dx%d, rendering %dx%d on %s; %d module(s) installed; press H "
           "for help\n",
           scene_path, fw, fh, opts.width, opts.height, st_context_renderer(), v->num_mods);
    fflush(stdout);

    if (script) {
        rc = view_run_script(v, script, script_f);
        script_f = NULL; // closed by view_run_script
    } else {
        while (!v->quit) {
            if (!view_frame(v, &err)) goto fail;
        }
    }
    goto done;
fail:
    rc = st_report("view", &err);
done:
    if (script_f) fclose(script_f);
    if (v->world) st_world_destroy(v->world);
    if (v->ctx) view_gl_free(&v->gl);
    st_context_destroy(v->ctx);
    free(v->prev_totals);
    free(v);
    st_scene_free(&scene);
    return rc;
}
