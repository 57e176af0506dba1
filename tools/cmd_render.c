// strahl render: headless frames of a scene to EXR (linear radiance) or PNG,
// with per-pass statistics.
#define _GNU_SOURCE
#include "cmd_common.h"
#include "st_cmd.h"
#include "st_file.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>

#define MAX_SETS 64

static const char help_text[] =
    "usage: strahl render SCENE.json -o OUT.exr|OUT.png [options]\n"
    "Renders frames of a scene headless (EGL) and writes the last one: EXR (linear\n"
    "radiance, 32-bit float R,G,B) or PNG (sRGB, 8 bit).\n"
    "  -o OUT.exr|OUT.png       output file (required; written atomically)\n"
    "  --set MODULE.PARAM=VALUE change a module parameter (repeatable; default: the scene's)\n"
    "  --size WxH               image size (default: the scene's image.width x height)\n"
    "  --filter box|point       pixel filter (default: the scene's image.filter, box):\n"
    "                           box = mean radiance over the pixel (jittered frames\n"
    "                           accumulated until converged), point = pixel centres\n"
    "  --frames N               render exactly N frames, 1..100000 (box: their mean; default:\n"
    "                           run until every progressive module, e.g. atlas_gi's gather,\n"
    "                           and the box filter report the image converged; 1 frame if\n"
    "                           none is progressive)\n"
    "  --max-frames N           cap on frames when running to convergence (default 2000)\n"
    "  --max-seconds S          cap on seconds when running to convergence (default 600)\n"
    "  --warmup W               frames not timed, 0..100000 (default 1 if N > 1, else 0)\n"
    "  --stats, --stats=json    print per-pass runs/skips/culls and median GPU/CPU times\n"
    "  --exposure EV            PNG exposure in stops, -64..64 (default 0)\n"
    "  --allow-outside-assets   let glTF buffer/image URIs and VDB files leave their folder\n"
    "                           (default: refused)\n"
    "  -h, --help               this text\n"
    "example:\n"
    "  strahl render scenes/cornell.json -o out/cornell.png --stats\n";

// The GPU memory table: every target and buffer by name, then per owner.
static void print_memory(st_world *w, bool json) {
    enum { MAX_ROWS = 320 };
    static st_mem_entry rows[MAX_ROWS];
    int n = st_world_memory(w, rows, MAX_ROWS);
    n = n < MAX_ROWS ? n : MAX_ROWS;
    size_t total = 0;
    for (int i = 0; i < n; i++)
        total += rows[i].bytes;
    if (json) {
        printf("\"memory\": [");
        for (int i = 0; i < n; i++) {
            const st_mem_entry *e = &rows[i];
            printf("%s\n  {\"name\": \"%s\", \"owner\": \"%s\", \"kind\": \"%s\", "
                   "\"format\": \"%s\", \"width\": %d, \"height\": %d, \"layers\": %d, "
                   "\"levels\": %d, \"bytes\": %zu}",
                   i ? "," : "", e->name, e->owner, e->kind, e->format, e->width, e->height,
                   e->layers, e->levels, e->bytes);
        }
        printf("\n], \"memory_by_owner\": {");
    } else {
        printf("%-32s %-10s %-14s %-14s %11s %6s %6s %12s\n", "GPU memory", "owner", "kind",
               "format", "size", "layers", "levels", "bytes");
        for (int i = 0; i < n; i++) {
            const st_mem_entry *e = &rows[i];
            char size[32] = "-";
            if (e->width) snprintf(size, sizeof size, "%dx%d", e->width, e->height);
            printf("%-32s %-10s %-14s %-14s %11s %6d %6d %12zu\n", e->name, e->owner, e->kind,
                   e->format, size, e->layers, e->levels, e->bytes);
        }
    }
    // Rows of one owner are adjacent.
    for (int i = 0, k = 0; i < n; k++) {
        size_t sum = 0;
        int j = i;
        for (; j < n && !strcmp(rows[j].owner, rows[i].owner); j++)
            sum += rows[j].bytes;
        if (json)
            printf("%s\"%s\": %zu", k ? ", " : "", rows[i].owner, sum);
        else
            printf("%-32s %-10s %12.3f MiB\n", k ? "" : "GPU memory per owner", rows[i].owner,
                   sum / 1048576.0);
        i = j;
    }
    if (json)
        printf("}, ");
    else
        printf("%-32s %-10s %12.3f MiB (%zu bytes)\n", "GPU memory total", "", total / 1048576.0,
               total);
}

static void print_stats(st_world *w, const float *frame_ms, int nframes, bool json,
                        const st_progress *pr, long ran, double total_ms) {
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double fm = st_median_f(frame_ms, nframes);
    const st_camera *c = st_world_camera(w);
    if (json) {
        printf("{\"renderer\": \"%s\", \"width\": %d, \"height\": %d, \"filter\": \"%s\", "
               "\"frames\": %d, \"frame_ms_median\": %.4f, \"peak_rss_kb\": %ld, "
               "\"gpu_bytes\": %zu, ",
               st_context_renderer(), c->width, c->height,
               st_filter_name(st_world_scene(w)->filter), nframes, fm, ru.ru_maxrss,
               st_world_memory_bytes(w));
        print_memory(w, true);
        if (pr)
            printf("\"frames_run\": %ld, \"total_ms\": %.3f, \"converged\": %s, \"error\": %.6g, "
                   "\"progress_info\": \"%s\", ",
                   ran, total_ms, pr->converged ? "true" : "false",
                   isfinite(pr->error) ? pr->error : -1.0, pr->info);
        printf("\"passes\": [");
        for (int i = 0; i < st_world_num_pass_stats(w); i++) {
            const st_pass_stats *s = st_world_pass_stats(w, i);
            printf("%s\n  {\"module\": \"%s\", \"pass\": \"%s\", \"runs\": %u, \"skipped\": %u, "
                   "\"culled\": %u, \"gpu_ms_median\": %.4f, \"cpu_ms_median\": %.4f}",
                   i ? "," : "", s->module, s->pass, s->runs, s->skipped, s->culled,
                   st_median_f(s->gpu_ms, s->num_samples), st_median_f(s->cpu_ms, s->num_samples));
        }
        printf("\n]}\n");
        return;
    }
    printf("renderer: %s, %dx%d, %d frame(s) timed, median frame %.3f ms, peak RSS %.1f MiB, "
           "GPU allocations %.1f MiB\n",
           st_context_renderer(), c->width, c->height, nframes, fm, ru.ru_maxrss / 1024.0,
           st_world_memory_bytes(w) / 1048576.0);
    if (pr)
        printf("%s after %ld frame(s), %.0f ms, estimated remaining relative error %.4g%s%s\n",
               pr->converged ? "converged" : "not converged", ran, total_ms, pr->error,
               pr->info[0] ? "\n" : "", pr->info);
    printf("%-12s %-14s %6s %8s %7s %12s %12s\n", "module", "pass", "runs", "skipped", "culled",
           "gpu ms (med)", "cpu ms (med)");
    for (int i = 0; i < st_world_num_pass_stats(w); i++) {
        const st_pass_stats *s = st_world_pass_stats(w, i);
        printf("%-12s %-14s %6u %8u %7u %12.3f %12.3f\n", s->module, s->pass, s->runs, s->skipped,
               s->culled, st_median_f(s->gpu_ms, s->num_samples),
               st_median_f(s->cpu_ms, s->num_samples));
    }
    print_memory(w, false);
}

typedef struct render_args {
    const char *scene_path, *out, *filter_arg;
    char *sets[MAX_SETS];
    int num_sets, width, height, stats; // stats: 0 off, 1 text, 2 JSON
    long frames, warmup, max_frames;
    double max_seconds, exposure;
    bool frames_given;
} render_args;

// Options with a checked value; *known says whether `a` is one of them.
static bool parse_value(void *ctx, const char *a, const char *v, bool *known, st_err *err) {
    render_args *r = ctx;
    char *e;
    *known = true;
    if (!strcmp(a, "-o")) {
        r->out = v;
    } else if (!strcmp(a, "--set")) {
        if (r->num_sets == MAX_SETS) return st_fail(err, ST_ERR_INPUT, "too many --set");
        r->sets[r->num_sets++] = (char *)v;
    } else if (!strcmp(a, "--size")) {
        if (!st_parse_size(v, &r->width, &r->height))
            return st_fail(err, ST_ERR_INPUT, "--size %s: expected WxH, 1..16384 each", v);
    } else if (!strcmp(a, "--frames")) {
        if (!st_parse_int(v, 1, 100000, &r->frames))
            return st_fail(err, ST_ERR_INPUT, "--frames %s: expected 1..100000", v);
        r->frames_given = true;
    } else if (!strcmp(a, "--filter")) {
        st_pixel_filter f;
        if (!st_filter_parse(v, &f))
            return st_fail(err, ST_ERR_INPUT, "--filter %s: expected box or point", v);
        r->filter_arg = v;
    } else if (!strcmp(a, "--max-frames")) {
        if (!st_parse_int(v, 1, 100000, &r->max_frames))
            return st_fail(err, ST_ERR_INPUT, "--max-frames %s: expected 1..100000", v);
    } else if (!strcmp(a, "--max-seconds")) {
        r->max_seconds = strtod(v, &e);
        if (*e || !isfinite(r->max_seconds) || r->max_seconds <= 0 || r->max_seconds > 1e6)
            return st_fail(err, ST_ERR_INPUT, "--max-seconds %s: expected a number in (0, 1e6]", v);
    } else if (!strcmp(a, "--warmup")) {
        if (!st_parse_int(v, 0, 100000, &r->warmup))
            return st_fail(err, ST_ERR_INPUT, "--warmup %s: expected 0..100000", v);
    } else if (!strcmp(a, "--exposure")) {
        r->exposure = strtod(v, &e);
        if (*e || !isfinite(r->exposure) || fabs(r->exposure) > 64)
            return st_fail(err, ST_ERR_INPUT,
                           "--exposure %s: expected a number of stops in [-64, 64]", v);
    } else {
        *known = false;
    }
    return true;
}

static bool render_flag(void *ctx, const char *a) {
    render_args *r = ctx;
    if (!strcmp(a, "--stats")) return r->stats = 1, true;
    if (!strcmp(a, "--stats=json")) return r->stats = 2, true;
    return false;
}

// Fills r from argv and settles frames and warm-up; *help: -h was given
// (the text is printed).
static bool parse_args(render_args *r, int argc, char **argv, bool *help, st_err *err) {
    static const st_argv_spec spec = {help_text, "", parse_value, render_flag};
    if (!st_cmd_walk_args(&spec, r, argc, argv, &r->scene_path, help, err)) return false;
    if (*help) return true;
    if (!r->scene_path || !r->out)
        return st_fail(err, ST_ERR_INPUT,
                       "usage: strahl render SCENE.json -o OUT.exr|OUT.png [options] (see --help)");
    static const char *const exts[] = {"exr", "png", NULL};
    const char *inputs[] = {r->scene_path, NULL};
    if (!st_check_output("-o", r->out, exts, inputs, err)) return false;
    // Without --frames a still image is a converged one: frames run until
    // every progressive module reports convergence (or a cap is reached).
    if (!r->frames_given) r->frames = r->max_frames;
    if (r->warmup < 0) r->warmup = r->frames > 1 && r->frames_given ? 1 : 0;
    if (r->warmup >= r->frames) r->warmup = r->frames - 1;
    return true;
}

// What the frames did: their times after the warm-up, how many ran, the
// last progress report.
typedef struct run_result {
    float *frame_ms;
    int timed;
    long ran;
    double total_ms;
    st_progress prog;
    bool has_prog;
} run_result;

// Runs the frames (until converged without --frames).
static bool run_frames(const render_args *r, st_world *w, run_result *o, st_err *err) {
    bool until_converged = !r->frames_given;
    double start = st_now_ms();
    o->prog = (st_progress){.converged = true};
    for (long f = 0; f < r->frames; f++) {
        if (f == r->warmup) st_world_reset_samples(w);
        double t0 = st_now_ms();
        if (!st_world_frame(w, err)) return false;
        glFinish();
        if (f >= r->warmup) o->frame_ms[o->timed++] = (float)(st_now_ms() - t0);
        o->ran++;
        o->has_prog = st_world_progress(w, &o->prog);
        if (until_converged &&
            (!o->has_prog || o->prog.converged || st_now_ms() - start > 1000 * r->max_seconds))
            break;
    }
    o->total_ms = st_now_ms() - start;
    return true;
}

// The image (EXR with the filter in its header, or PNG with the exposure);
// nothing is written if a value is not finite.
static bool write_image(const render_args *r, const st_image *img, st_pixel_filter filter,
                        st_err *err) {
    size_t bad = st_image_count_nonfinite(img);
    if (bad)
        return st_fail(err, ST_ERR_RUNTIME,
                       "%zu non-finite values in the rendered image; nothing written", bad);
    const char *dot = strrchr(r->out, '.');
    static const char *const rgb[] = {"R", "G", "B"};
    st_exr_meta meta = {0}; // the EXR header records the pixel filter
    snprintf(meta.filter, sizeof meta.filter, "%s", st_filter_name(filter));
    return strcasecmp(dot, ".exr") ? st_image_write(r->out, img, (float)r->exposure, err)
                                   : st_image_write_exr_meta(r->out, img, rgb, &meta, err);
}

int st_cmd_render(int argc, char **argv) {
    render_args r = {.frames = 1, .warmup = -1, .max_frames = 2000, .max_seconds = 600};
    st_err err = {0};
    bool help;
    if (!parse_args(&r, argc, argv, &help, &err)) return st_report("render", &err);
    if (help) return ST_EXIT_OK;
    st_scene scene = {0};
    if (!st_load_scene_with(r.scene_path, r.sets, r.num_sets, r.width, r.height, &scene, &err))
        return st_report("render", &err);
    // Only the loaded scene knows its glTF, buffer and VDB files.
    if (!st_scene_check_output(&scene, "-o", r.out, &err)) {
        st_scene_free(&scene);
        return st_report("render", &err);
    }
    if (r.filter_arg) st_filter_parse(r.filter_arg, &scene.filter);
    st_context *ctx = st_context_create_headless(&err);
    st_world *w = NULL;
    run_result res = {.frame_ms = calloc((size_t)r.frames, sizeof *res.frame_ms)};
    st_image img = {0};
    bool ok = ctx && res.frame_ms;
    if (ok) {
        st_world_opts opts = {.timing = r.stats != 0, .filter = scene.filter};
        // --frames N: the box filter's mean of exactly N frames.
        if (r.frames_given) opts.filter_max_frames = (int)r.frames, opts.filter_tolerance = -1;
        w = st_world_create(&scene, &opts, &err);
    }
    ok = ok && w && run_frames(&r, w, &res, &err) && st_world_read(w, &img, &err) &&
         write_image(&r, &img, scene.filter, &err);
    if (ok && r.stats)
        print_stats(w, res.frame_ms, res.timed, r.stats == 2, res.has_prog ? &res.prog : NULL,
                    res.ran, res.total_ms);
    else if (ok && res.has_prog)
        printf("strahl render: %s after %ld frame(s), %.0f ms, estimated remaining relative error "
               "%.4g\n",
               res.prog.converged ? "converged" : "not converged", res.ran, res.total_ms,
               res.prog.error);
    int rc = ok ? ST_EXIT_OK : st_report("render", &err);
    st_image_free(&img);
    st_world_destroy(w);
    st_context_destroy(ctx);
    st_scene_free(&scene);
    free(res.frame_ms);
    return rc;
}
