// strahl reference: the CPU reference image of a scene (tools/reference),
// box-filtered over each pixel unless the scene or --filter says point.
// Writes R, G, B (radiance of the chosen AOV) and stderr.R/G/B (standard
// error of each pixel's mean) to an EXR; nothing is written on failure.
#define _POSIX_C_SOURCE 200809L
#include "cmd_common.h"
#include "reference/ref.h"
#include "st_cmd.h"
#include "st_file.h"
#include "st_image.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define MAX_SETS 64

static const char usage_text[] =
    "usage: strahl reference SCENE.json -o OUT.exr [options]\n"
    "The CPU reference (Embree, all cores): R, G, B and the per-pixel standard error\n"
    "of the mean (stderr.R/G/B); the header records spp and the seed (strahl merge reads them).\n"
    "  -o OUT.exr                output (required; .exr only, written atomically)\n"
    "  --spp N                   samples per pixel, 1..10000000 (default 64)\n"
    "  --target-error E          add samples (passes with seeds derived from --seed, the\n"
    "                            first with --spp) until the image's estimated relative\n"
    "                            error sqrt(mean stderr^2) / mean falls to E, in (0, 1);\n"
    "                            the header's spp is the total reached\n"
    "  --aov combined|direct|indirect|inscatter   what to render (default combined)\n"
    "  --seed S                  random seed, unsigned 64-bit (default 0); runs with\n"
    "                            different seeds are independent shards for strahl merge\n"
    "  --size WxH                image size (default: the scene's)\n"
    "  --bounces K               diffuse bounces, 0..16 (default 1)\n"
    "  --bounce-visibility on|off  visibility test in the bounce (default on)\n"
    "  --estimator area|thesis   bounce estimator (default area)\n"
    "  --steps N                 strata per view ray for in-scattering, 1..1000000 (default 256)\n"
    "  --sampler sobol|independent  random numbers (default sobol): Owen-scrambled Sobol\n"
    "                            points in 16 independently scrambled batches per pixel\n"
    "                            (stderr from the batch means), or independent numbers\n"
    "  --filter box|point        pixel filter (default: the scene's image.filter, box): box =\n"
    "                            samples stratified over the pixel's square, point = its centre;\n"
    "                            recorded in the header as strahl.filter\n"
    "  --threads N               worker threads, 1..256 (default: all online cores)\n"
    "  --set MODULE.PARAM=VALUE  checked against the scene's modules like render (repeatable)\n"
    "  --allow-outside-assets    let glTF buffer/image URIs and VDB files leave their folder\n"
    "                            (default: refused)\n" ST_CMD_SCENE_HELP
    "  -h, --help                this text\n"
    "Progress with an ETA is shown on a terminal (stderr), one summary line otherwise.\n"
    "example:\n"
    "  strahl reference scenes/godrays_window.json -o ref.exr --size 128x128 --spp 64 --bounces "
    "0\n";

static bool parse_choice(const char *s, const char *const *names, int n, int *out) {
    for (int i = 0; i < n; i++)
        if (!strcmp(s, names[i])) {
            *out = i;
            return true;
        }
    return false;
}

static bool parse_u64(const char *s, uint64_t *out) {
    char *e;
    errno = 0;
    if (!s[0] || s[0] == '-') return false;
    unsigned long long v = strtoull(s, &e, 10);
    if (*e || errno) return false;
    *out = v;
    return true;
}

static void on_rows(void *user, int done, int rows) {
    (void)rows;
    st_progress_update(user, done, NULL);
}

static bool bad(st_err *err, const char *fmt, const char *arg) {
    return st_fail(err, ST_ERR_INPUT, fmt, arg);
}

typedef struct ref_args {
    const char *scene_path, *out_path;
    char *sets[MAX_SETS];
    int num_sets, width, height;
    int filter;    // -1: the scene's
    double target; // --target-error; 0: none
    st_ref_options o;
} ref_args;

// The choice options (--aov, --bounce-visibility, --estimator, --sampler,
// --filter);
// *known says whether `a` is one of them.
static bool parse_choice_option(ref_args *r, const char *a, const char *v, bool *known,
                                st_err *err) {
    int choice;
    *known = true;
    if (!strcmp(a, "--aov")) {
        static const char *const names[] = {"combined", "direct", "indirect", "inscatter"};
        if (!parse_choice(v, names, 4, &choice))
            return bad(err, "--aov %s: expected combined, direct, indirect or inscatter", v);
        r->o.aov = (st_ref_aov)choice;
    } else if (!strcmp(a, "--bounce-visibility")) {
        static const char *const names[] = {"on", "off"};
        if (!parse_choice(v, names, 2, &choice))
            return bad(err, "--bounce-visibility %s: expected on or off", v);
        r->o.no_visibility = choice == 1;
    } else if (!strcmp(a, "--estimator")) {
        static const char *const names[] = {"area", "thesis"};
        if (!parse_choice(v, names, 2, &choice))
            return bad(err, "--estimator %s: expected area or thesis", v);
        r->o.estimator = (st_ref_estimator)choice;
    } else if (!strcmp(a, "--sampler")) {
        static const char *const names[] = {"sobol", "independent"};
        if (!parse_choice(v, names, 2, &choice))
            return bad(err, "--sampler %s: expected sobol or independent", v);
        r->o.sampler = (st_ref_sampler)choice;
    } else if (!strcmp(a, "--filter")) {
        static const char *const names[] = {"point", "box"};
        if (!parse_choice(v, names, 2, &choice))
            return bad(err, "--filter %s: expected box or point", v);
        r->filter = choice;
    } else {
        *known = false;
    }
    return true;
}

// Option a with its value v (every option takes one).
static bool parse_option(ref_args *r, const char *a, const char *v, st_err *err) {
    long n;
    bool known;
    if (!parse_choice_option(r, a, v, &known, err)) return false;
    if (known) return true;
    if (!strcmp(a, "-o")) {
        r->out_path = v;
    } else if (!strcmp(a, "--spp")) {
        if (!st_parse_int(v, 1, 10000000, &n)) return bad(err, "--spp %s: expected 1..10000000", v);
        r->o.spp = (int)n;
    } else if (!strcmp(a, "--target-error")) {
        char *e;
        errno = 0;
        r->target = strtod(v, &e);
        if (*e || errno || !(r->target > 0.0 && r->target < 1.0))
            return bad(err, "--target-error %s: expected a relative error in (0, 1)", v);
    } else if (!strcmp(a, "--seed")) {
        if (!parse_u64(v, &r->o.seed))
            return bad(err, "--seed %s: expected an unsigned integer", v);
    } else if (!strcmp(a, "--size")) {
        if (!st_parse_size(v, &r->width, &r->height))
            return bad(err, "--size %s: expected WxH, 1..16384 each", v);
    } else if (!strcmp(a, "--bounces")) {
        if (!st_parse_int(v, 0, 16, &n)) return bad(err, "--bounces %s: expected 0..16", v);
        r->o.bounces = (int)n;
    } else if (!strcmp(a, "--steps")) {
        if (!st_parse_int(v, 1, 1000000, &n)) return bad(err, "--steps %s: expected 1..1000000", v);
        r->o.march_steps = (int)n;
    } else if (!strcmp(a, "--threads")) {
        if (!st_parse_int(v, 1, 256, &n)) return bad(err, "--threads %s: expected 1..256", v);
        r->o.threads = (int)n;
    } else if (!strcmp(a, "--set")) {
        if (r->num_sets == MAX_SETS) return bad(err, "%s: too many --set options", a);
        r->sets[r->num_sets++] = (char *)v;
    } else {
        return bad(err, "%s: unknown option", a);
    }
    return true;
}

// Fills r from argv; *help: -h was given (the text is printed).
static bool parse_args(ref_args *r, int argc, char **argv, bool *help, st_err *err) {
    *help = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage_text, stdout);
            *help = true;
            return true;
        } else if (st_cmd_scene_option(a)) {
            continue;
        } else if (a[0] != '-') {
            if (r->scene_path) return bad(err, "unexpected argument '%s' (one scene only)", a);
            r->scene_path = a;
            continue;
        } else if (!v) {
            return bad(err, "%s: unknown option or missing value", a);
        }
        bool known = false;
        if (!st_cmd_scene_value(a, v, &known, err)) return false;
        i++; // every option takes a value
        if (!known && !parse_option(r, a, v, err)) return false;
    }
    if (!r->scene_path) return bad(err, "%s", "missing SCENE.json");
    if (!r->out_path) return bad(err, "%s", "missing -o OUT.exr");
    static const char *const exts[] = {"exr", NULL};
    const char *inputs[] = {r->scene_path, NULL};
    return st_check_output("-o", r->out_path, exts, inputs, err);
}

// The EXR with its header: spp, filter, seed and the config that shards
// must share to merge. w0 x h0 is the scene's image size.
static bool write_reference(const ref_args *r, const st_image *img, int w0, int h0, st_err *err) {
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    const st_ref_options *o = &r->o;
    st_exr_meta meta = {.spp = o->spp};
    snprintf(meta.filter, sizeof meta.filter, "%s", st_filter_name(o->filter));
    snprintf(meta.seeds, sizeof meta.seeds, "%llu", (unsigned long long)o->seed);
    // What the pixels depend on besides spp and seed (--set is not: the
    // reference reads no module): shards merge only if this matches.
    static const char *const aovs[] = {"combined", "direct", "indirect", "inscatter"};
    snprintf(meta.config, sizeof meta.config,
             "%s %dx%d aov=%s bounces=%d visibility=%s estimator=%s steps=%d filter=%s "
             "sampler=%s",
             r->scene_path, w0, h0, aovs[o->aov], o->bounces, o->no_visibility ? "off" : "on",
             o->estimator == ST_REF_EST_THESIS ? "thesis" : "area",
             o->march_steps > 0 ? o->march_steps : 256, meta.filter,
             o->sampler == ST_REF_SAMPLER_INDEPENDENT ? "independent" : "sobol");
    return st_image_write_exr_meta(r->out_path, img, names, &meta, err);
}

int st_cmd_reference(int argc, char **argv) {
    ref_args r = {.filter = -1, .o = {.spp = 64, .bounces = 1}};
    st_err err = {0};
    bool help;
    if (!parse_args(&r, argc, argv, &help, &err)) return st_report("reference", &err);
    if (help) return ST_EXIT_OK;
    st_scene scene;
    // --set is checked against the scene's modules like `render` does, so the
    // same command line serves both; the reference itself reads no module.
    if (!st_load_scene_with(r.scene_path, r.sets, r.num_sets, r.width, r.height, &scene, &err))
        return st_report("reference", &err);
    // Only the loaded scene knows its glTF, buffer and VDB files; a medium
    // too dense to track is refused before the render starts.
    if (!st_scene_check_output(&scene, "-o", r.out_path, &err) ||
        !st_ref_medium_check(&scene, &err)) {
        st_scene_free(&scene);
        return st_report("reference", &err);
    }
    r.o.filter = r.filter >= 0 ? (st_pixel_filter)r.filter : scene.filter;
    st_image img;
    const int w0 = scene.width, h0 = scene.height;
    double t0 = st_now_ms();
    st_progress_bar bar;
    st_progress_begin(&bar, "reference", "rows", h0);
    r.o.progress = on_rows;
    r.o.progress_user = &bar;
    long spp = r.o.spp;
    double reached = 0.0;
    bool ok = r.target > 0.0 ? st_ref_render_target(&scene, &r.o, r.target, 10000000, &img, &spp,
                                                    &reached, &err)
                             : st_ref_render(&scene, &r.o, &img, &err);
    if (ok && r.target <= 0.0) reached = st_ref_relative_error(&img);
    r.o.spp = (int)spp; // the header records the samples reached
    double secs = (st_now_ms() - t0) / 1000.0;
    // On a terminal the bar ends here; otherwise the stdout line below is the summary.
    if (bar.tty) st_progress_end(&bar, ok ? h0 : 0, NULL);
    st_scene_free(&scene);
    if (!ok) return st_report("reference", &err);
    size_t bad_px = st_image_count_nonfinite(&img);
    if (bad_px) {
        st_image_free(&img);
        st_fail(&err, ST_ERR_RUNTIME, "%zu non-finite values in the result; nothing written",
                bad_px);
        return st_report("reference", &err);
    }
    ok = write_reference(&r, &img, w0, h0, &err);
    int w = img.width, h = img.height;
    st_image_free(&img);
    if (!ok) return st_report("reference", &err);
    printf("strahl reference: %s (%dx%d, %d spp, %.2f s, estimated relative error %.3g)\n",
           r.out_path, w, h, r.o.spp, secs, reached);
    return ST_EXIT_OK;
}
