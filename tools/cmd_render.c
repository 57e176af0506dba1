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
    "  --allow-outside-assets   let glTF buffer/image URIs leave the glTF file's folder\n"
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

int st_cmd_render(int argc, char **argv) {
    const char *scene_path = NULL, *out = NULL;
    char *sets[MAX_SETS];
    int num_sets = 0, width = 0, height = 0, stats = 0;
    long frames = 1, warmup = -1, max_frames = 2000;
    double max_seconds = 600;
    bool frames_given = false;
    const char *filter_arg = NULL;
    double exposure = 0;
    st_err err = {0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool has_next = i + 1 < argc;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(help_text, stdout);
            return ST_EXIT_OK;
        } else if (!strcmp(a, "-o") && has_next) {
            out = argv[++i];
        } else if (!strcmp(a, "--set") && has_next) {
            if (num_sets == MAX_SETS)
                return st_fail(&err, ST_ERR_INPUT, "too many --set"), st_report("render", &err);
            sets[num_sets++] = argv[++i];
        } else if (!strcmp(a, "--size") && has_next) {
            if (!st_parse_size(argv[++i], &width, &height))
                return st_fail(&err, ST_ERR_INPUT, "--size %s: expected WxH, 1..16384 each",
                               argv[i]),
                       st_report("render", &err);
        } else if (!strcmp(a, "--frames") && has_next) {
            if (!st_parse_int(argv[++i], 1, 100000, &frames))
                return st_fail(&err, ST_ERR_INPUT, "--frames %s: expected 1..100000", argv[i]),
                       st_report("render", &err);
            frames_given = true;
        } else if (!strcmp(a, "--filter") && has_next) {
            st_pixel_filter f;
            if (!st_filter_parse(argv[++i], &f))
                return st_fail(&err, ST_ERR_INPUT, "--filter %s: expected box or point", argv[i]),
                       st_report("render", &err);
            filter_arg = argv[i];
        } else if (!strcmp(a, "--max-frames") && has_next) {
            if (!st_parse_int(argv[++i], 1, 100000, &max_frames))
                return st_fail(&err, ST_ERR_INPUT, "--max-frames %s: expected 1..100000", argv[i]),
                       st_report("render", &err);
        } else if (!strcmp(a, "--max-seconds") && has_next) {
            char *e;
            max_seconds = strtod(argv[++i], &e);
            if (*e || !isfinite(max_seconds) || max_seconds <= 0 || max_seconds > 1e6)
                return st_fail(&err, ST_ERR_INPUT,
                               "--max-seconds %s: expected a number in (0, 1e6]", argv[i]),
                       st_report("render", &err);
        } else if (!strcmp(a, "--warmup") && has_next) {
            if (!st_parse_int(argv[++i], 0, 100000, &warmup))
                return st_fail(&err, ST_ERR_INPUT, "--warmup %s: expected 0..100000", argv[i]),
                       st_report("render", &err);
        } else if (!strcmp(a, "--exposure") && has_next) {
            char *e;
            exposure = strtod(argv[++i], &e);
            if (*e || !isfinite(exposure) || fabs(exposure) > 64)
                return st_fail(&err, ST_ERR_INPUT,
                               "--exposure %s: expected a number of stops in [-64, 64]", argv[i]),
                       st_report("render", &err);
        } else if (!strcmp(a, "--stats")) {
            stats = 1;
        } else if (!strcmp(a, "--stats=json")) {
            stats = 2;
        } else if (st_cmd_scene_option(a)) {
        } else if (a[0] == '-' || scene_path) {
            return st_fail(&err, ST_ERR_INPUT, "unexpected argument '%s'", a),
                   st_report("render", &err);
        } else {
            scene_path = a;
        }
    }
    if (!scene_path || !out)
        return st_fail(&err, ST_ERR_INPUT,
                       "usage: strahl render SCENE.json -o OUT.exr|OUT.png [options] (see --help)"),
               st_report("render", &err);
    static const char *const exts[] = {"exr", "png", NULL};
    const char *inputs[] = {scene_path, NULL};
    if (!st_check_output("-o", out, exts, inputs, &err)) return st_report("render", &err);
    // Without --frames a still image is a converged one: frames run until
    // every progressive module reports convergence (or a cap is reached).
    bool until_converged = !frames_given;
    if (until_converged) frames = max_frames;
    if (warmup < 0) warmup = frames > 1 && !until_converged ? 1 : 0;
    if (warmup >= frames) warmup = frames - 1;

    st_scene scene = {0};
    if (!st_load_scene_with(scene_path, sets, num_sets, width, height, &scene, &err))
        return st_report("render", &err);
    if (filter_arg) st_filter_parse(filter_arg, &scene.filter);
    int rc = ST_EXIT_OK;
    st_context *ctx = st_context_create_headless(&err);
    st_world *w = NULL;
    float *frame_ms = calloc((size_t)frames, sizeof *frame_ms);
    st_image img = {0};
    if (!ctx || !frame_ms) goto fail;
    st_world_opts opts = {.timing = stats != 0, .filter = scene.filter};
    // --frames N: the box filter's mean of exactly N frames.
    if (frames_given) opts.filter_max_frames = (int)frames, opts.filter_tolerance = -1;
    w = st_world_create(&scene, &opts, &err);
    if (!w) goto fail;
    int timed = 0;
    long ran = 0;
    double start = st_now_ms();
    st_progress prog = {.converged = true};
    bool has_prog = false;
    for (long f = 0; f < frames; f++) {
        if (f == warmup) st_world_reset_samples(w);
        double t0 = st_now_ms();
        if (!st_world_frame(w, &err)) goto fail;
        glFinish();
        if (f >= warmup) frame_ms[timed++] = (float)(st_now_ms() - t0);
        ran++;
        has_prog = st_world_progress(w, &prog);
        if (until_converged &&
            (!has_prog || prog.converged || st_now_ms() - start > 1000 * max_seconds))
            break;
    }
    double total_ms = st_now_ms() - start;
    if (!st_world_read(w, &img, &err)) goto fail;
    size_t bad = st_image_count_nonfinite(&img);
    if (bad) {
        st_fail(&err, ST_ERR_RUNTIME,
                "%zu non-finite values in the rendered image; nothing written", bad);
        goto fail;
    }
    const char *dot = strrchr(out, '.');
    static const char *const rgb[] = {"R", "G", "B"};
    st_exr_meta meta = {0}; // the EXR header records the pixel filter
    snprintf(meta.filter, sizeof meta.filter, "%s", st_filter_name(scene.filter));
    if (!(strcasecmp(dot, ".exr") ? st_image_write(out, &img, (float)exposure, &err)
                                  : st_image_write_exr_meta(out, &img, rgb, &meta, &err)))
        goto fail;
    if (stats)
        print_stats(w, frame_ms, timed, stats == 2, has_prog ? &prog : NULL, ran, total_ms);
    else if (has_prog)
        printf("strahl render: %s after %ld frame(s), %.0f ms, estimated remaining relative error "
               "%.4g\n",
               prog.converged ? "converged" : "not converged", ran, total_ms, prog.error);
    goto done;
fail:
    rc = st_report("render", &err);
done:
    st_image_free(&img);
    st_world_destroy(w);
    st_context_destroy(ctx);
    st_scene_free(&scene);
    free(frame_ms);
    return rc;
}
