// strahl render: headless frames of a scene to EXR (linear radiance) or PNG,
// with per-pass statistics.
#define _GNU_SOURCE
#include "cmd_common.h"
#include "render_status.h"
#include "st_cmd.h"
#include "st_file.h"
#include "st_still.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <strings.h>
#include <sys/resource.h>

#define MAX_SETS 64
#define MAX_OUTS 8

static const char help_text[] =
    "usage: strahl render SCENE.json -o OUT.exr|OUT.png [-o OUT2...] [options]\n"
    "Renders frames of a scene headless (EGL) and writes the last one: EXR (linear\n"
    "radiance, 32-bit float R,G,B) or PNG (sRGB, 8 bit).\n"
    "  -o OUT.exr|OUT.png       output file (required; written atomically); repeat it to\n"
    "                           write one still to several files (up to 8: EXR and PNG)\n"
    "  --set MODULE.PARAM=VALUE change a module parameter (repeatable; default: the scene's)\n"
    "  --size WxH               image size (default: the scene's image.width x height)\n"
    "  --filter box|point       pixel filter (default: the scene's image.filter, box):\n"
    "                           box = mean radiance over the pixel (jittered frames\n"
    "                           accumulated until converged), point = pixel centres\n"
    "  --frames N               render exactly N frames, 1..100000 (box: their mean; default:\n"
    "                           run until every progressive module, e.g. atlas_gi's gather,\n"
    "                           and the box filter report the image converged; 1 frame if\n"
    "                           none is progressive)\n"
    "  --max-frames N           cap on frames when running to convergence (default 2000;\n"
    "                           the box filter itself stops at 1024 accumulated frames,\n"
    "                           counted after every progressive module has settled)\n"
    "  --max-seconds S          cap on seconds when running to convergence (default 600)\n"
    "  --quiet                  no progress line (default: on a terminal, stderr shows one\n"
    "                           self-overwriting line: frames, estimated remaining error,\n"
    "                           ETA; elsewhere only the final line is printed, on stdout)\n"
    "  --warmup W               frames not timed, 0..100000 (default 1 if N > 1, else 0)\n"
    "  --stats, --stats=json    print per-pass runs/skips/culls and median GPU/CPU times\n"
    "  --exposure EV            PNG exposure in stops, -64..64 (default 0)\n"
    "  --error-map OUT.exr      box still: also write where its estimated error sits, per\n"
    "                           pixel |A - B| / 2 of the even and odd frames' means (its rms\n"
    "                           over the image's mean is the reported estimate)\n"
    "  --allow-outside-assets   let glTF buffer/image URIs and VDB files leave their folder\n"
    "                           (default: refused)\n" ST_CMD_SCENE_HELP
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

// st_stop's names in --stats=json ("stopped_by").
static const char *const stop_names[] = {"converged", "frames",      "max-frames",
                                         "cap",       "max-seconds", "filter-cap"};

static void print_stats(st_world *w, const float *frame_ms, int nframes, bool json,
                        const st_still_status *st, const char *line) {
    const st_progress *pr = st ? &st->prog : NULL;
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
                   "\"stopped_by\": \"%s\", \"progress_info\": \"%s\", ",
                   st->ran, st->total_ms, st->stop == ST_STOP_CONVERGED ? "true" : "false",
                   isfinite(pr->error) && st->ran > 1 ? pr->error : -1.0, stop_names[st->stop],
                   pr->info);
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
    if (pr) printf("%s%s%s\n", line, pr->info[0] ? "\n" : "", pr->info);
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
    const char *scene_path, *filter_arg;
    const char *outs[MAX_OUTS], *error_map;
    int num_outs;
    char *sets[MAX_SETS];
    int num_sets, width, height, stats; // stats: 0 off, 1 text, 2 JSON
    long frames, warmup, max_frames;
    double max_seconds, exposure;
    bool frames_given, max_frames_given, quiet;
} render_args;

// Options with a checked value; *known says whether `a` is one of them.
static bool parse_value(void *ctx, const char *a, const char *v, bool *known, st_err *err) {
    render_args *r = ctx;
    char *e;
    *known = true;
    if (!strcmp(a, "-o")) {
        if (r->num_outs == MAX_OUTS)
            return st_fail(err, ST_ERR_INPUT, "-o %s: at most %d outputs", v, MAX_OUTS);
        r->outs[r->num_outs++] = v;
    } else if (!strcmp(a, "--error-map")) {
        r->error_map = v;
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
        r->max_frames_given = true;
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
    if (!strcmp(a, "--quiet")) return r->quiet = true, true;
    return false;
}

// Output i: its extension, not an input, not an earlier output (each one
// is checked on its own, so a check of one output path slots in here).
static bool check_output(const render_args *r, int i, st_err *err) {
    static const char *const exts[] = {"exr", "png", NULL};
    const char *inputs[] = {r->scene_path, NULL};
    if (!st_check_output("-o", r->outs[i], exts, inputs, err)) return false;
    for (int k = 0; k < i; k++)
        if (!strcmp(r->outs[k], r->outs[i]) || st_same_file(r->outs[k], r->outs[i]))
            return st_fail(err, ST_ERR_INPUT, "-o %s: given twice", r->outs[i]);
    return true;
}

// --error-map: an EXR, not an input, not one of the -o outputs, and a box
// still of at least two frames (the filter is checked once the scene is
// loaded).
static bool check_error_map(const render_args *r, st_err *err) {
    static const char *const exts[] = {"exr", NULL};
    const char *inputs[] = {r->scene_path, NULL};
    if (!st_check_output("--error-map", r->error_map, exts, inputs, err)) return false;
    for (int k = 0; k < r->num_outs; k++)
        if (!strcmp(r->outs[k], r->error_map) || st_same_file(r->outs[k], r->error_map))
            return st_fail(err, ST_ERR_INPUT, "--error-map %s: also given as -o", r->error_map);
    if (r->filter_arg && strcmp(r->filter_arg, "box"))
        return st_fail(err, ST_ERR_INPUT, "--error-map needs the box filter (--filter %s)",
                       r->filter_arg);
    if ((r->frames_given && r->frames < 2) || (r->max_frames_given && r->max_frames < 2))
        return st_fail(err, ST_ERR_INPUT, "--error-map needs at least 2 frames");
    return true;
}

// The still loop's options (st_still.h) of the command line.
static st_still_opts still_opts(const render_args *r) {
    return (st_still_opts){.frames = r->frames,
                           .warmup = r->warmup,
                           .max_seconds = r->max_seconds,
                           .frames_given = r->frames_given,
                           .max_frames_given = r->max_frames_given};
}

// Fills r from argv and settles frames and warm-up; *help: -h was given
// (the text is printed).
static bool parse_args(render_args *r, int argc, char **argv, bool *help, st_err *err) {
    static const st_argv_spec spec = {help_text, "", parse_value, render_flag};
    if (!st_cmd_walk_args(&spec, r, argc, argv, &r->scene_path, help, err)) return false;
    if (*help) return true;
    if (!r->scene_path || !r->num_outs)
        return st_fail(err, ST_ERR_INPUT,
                       "usage: strahl render SCENE.json -o OUT.exr|OUT.png [options] (see --help)");
    for (int i = 0; i < r->num_outs; i++)
        if (!check_output(r, i, err)) return false;
    if (r->error_map && !check_error_map(r, err)) return false;
    st_still_opts s = still_opts(r);
    st_still_settle(&s, r->max_frames);
    r->frames = s.frames, r->warmup = s.warmup;
    return true;
}

// The progress line (and whether --frames fixed the count, for its ETA).
typedef struct progress_line {
    st_still_progress bar;
    bool frames_given;
} progress_line;

// After every frame (st_still_opts.on_frame).
static void show_progress(void *user, const st_still_status *st) {
    progress_line *p = user;
    st_still_progress_update(&p->bar, st, p->frames_given);
}

// A later write failed: the outputs written before it go too, so that a
// failed render leaves no partial output.
static void remove_outputs(const render_args *r, int n) {
    for (int i = 0; i < n; i++)
        unlink(r->outs[i]);
}

// The image to every output (EXR with the filter in its header, or PNG
// with the exposure); nothing is written if a value is not finite.
static bool write_images(const render_args *r, const st_image *img, st_pixel_filter filter,
                         st_err *err) {
    size_t bad = st_image_count_nonfinite(img);
    if (bad)
        return st_fail(err, ST_ERR_RUNTIME,
                       "%zu non-finite values in the rendered image; nothing written", bad);
    static const char *const rgb[] = {"R", "G", "B"};
    st_exr_meta meta = {0}; // the EXR header records the pixel filter
    snprintf(meta.filter, sizeof meta.filter, "%s", st_filter_name(filter));
    for (int i = 0; i < r->num_outs; i++) {
        const char *out = r->outs[i], *dot = strrchr(out, '.');
        bool ok = strcasecmp(dot, ".exr") ? st_image_write(out, img, (float)r->exposure, err)
                                          : st_image_write_exr_meta(out, img, rgb, &meta, err);
        if (!ok) return remove_outputs(r, i), false;
    }
    return true;
}

// The output checks that need the loaded scene: no output is one of its
// files, and an error map has a box still (the scene's filter or --filter).
static bool check_scene_outputs(const render_args *r, const st_scene *scene, st_err *err) {
    // Only the loaded scene knows its glTF, buffer and VDB files.
    for (int i = 0; i < r->num_outs; i++)
        if (!st_scene_check_output(scene, "-o", r->outs[i], err)) return false;
    if (!r->error_map) return true;
    if (scene->filter != ST_FILTER_BOX)
        return st_fail(err, ST_ERR_INPUT, "--error-map needs the box filter (the scene's is %s)",
                       st_filter_name(scene->filter));
    return st_scene_check_output(scene, "--error-map", r->error_map, err);
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
    if (r.filter_arg) st_filter_parse(r.filter_arg, &scene.filter);
    if (!check_scene_outputs(&r, &scene, &err)) {
        st_scene_free(&scene);
        return st_report("render", &err);
    }
    st_context *ctx = st_context_create_headless(&err);
    st_world *w = NULL;
    st_still_opts still = still_opts(&r);
    st_still_result res = {.frame_ms = calloc((size_t)r.frames, sizeof *res.frame_ms)};
    st_image img = {0}, emap = {0};
    bool ok = ctx && res.frame_ms;
    if (ok) {
        st_world_opts opts = st_still_world_opts(&scene, &still, r.stats != 0);
        w = st_world_create(&scene, &opts, &err);
    }
    progress_line progress = {.frames_given = r.frames_given};
    st_still_progress_begin(&progress.bar, r.quiet);
    still.on_frame = show_progress, still.user = &progress;
    ok = ok && w && st_still_run(w, &still, &res, &err) && st_world_read(w, &img, &err) &&
         (!r.error_map || st_world_read_error(w, &emap, &err)) &&
         write_images(&r, &img, scene.filter, &err);
    if (ok && r.error_map && !st_image_write(r.error_map, &emap, 0, &err))
        ok = false, remove_outputs(&r, r.num_outs);
    st_still_progress_end(&progress.bar);
    char line[1024];
    st_still_status_line(&res.st, line, sizeof line);
    if (ok && r.stats)
        print_stats(w, res.frame_ms, res.timed, r.stats == 2, res.st.has_prog ? &res.st : NULL,
                    line);
    else if (ok && res.st.has_prog)
        printf("strahl render: %s\n", line);
    int rc = ok ? ST_EXIT_OK : st_report("render", &err);
    st_image_free(&img);
    st_image_free(&emap);
    st_world_destroy(w);
    st_context_destroy(ctx);
    st_scene_free(&scene);
    free(res.frame_ms);
    return rc;
}
