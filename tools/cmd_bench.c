// strahl bench: run time against error. For every combination of the swept
// parameter values, render warm-up + F frames in a fresh world, record the
// median frame time, the median GPU time of each module's passes (timer
// queries), peak memory, and the error of the last frame against a reference
// image. --mode recompute (default) redoes cached passes every frame so the
// time is the technique's whole cost; steady times what a static scene
// costs per frame. Writes CSV, prints the Pareto front, draws a log-log plot (gnuplot).
#define _GNU_SOURCE
#include "cmd_common.h"
#include "cmd_shared.h"
#include "st_cmd.h"
#include "st_file.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <unistd.h>

#define MAX_SWEEPS 4
#define MAX_VALUES 32
#define MAX_SETS 32
#define MAX_ROWS 1024

typedef struct {
    char module[ST_NAME_MAX], param[ST_NAME_MAX];
    char values[MAX_VALUES][ST_NAME_MAX];
    int num_values;
} sweep;

typedef struct {
    char setting[256]; // "toth.samples=32 toth.scale=half"
    char curve[256];   // the setting without the first sweep's value
    double x;          // first sweep's numeric value (or index)
    double frame_ms, module_gpu_ms, module_cpu_ms;
    char passes[256]; // "pass=gpu ms;..." of the swept modules
    st_metrics m;
    double error, error_raw; // error with the reference's variance removed, and without
    bool noisy_ref;          // the reference's noise is > 1/3 of the error
    long peak_rss_kb;
    size_t gpu_bytes;
} row;

static const char help_text[] =
    "usage: strahl bench SCENE.json --reference REF.exr --sweep MODULE.PARAM=v1,v2,... --csv "
    "OUT.csv [options]\n"
    "Time against error: every combination of the swept values renders in a fresh world;\n"
    "one CSV row per setting, the Pareto front on stdout, optionally a log-log plot.\n"
    "When REF has standard-error channels (strahl reference), the error column has the\n"
    "reference's own variance removed (mean((a-b)^2 - s^2), see strahl compare --help);\n"
    "error_raw keeps the raw value, and one warning per run names the settings whose\n"
    "error the reference's noise cannot resolve (ref_noise_rms > debiased rmse / 3;\n"
    "ref_noise_warning = 1 in the CSV, hollow in the plot).\n"
    "  --reference REF.exr        reference image of the same size (required)\n"
    "  --sweep MODULE.PARAM=v,... values to sweep (required, up to 4; the first is the\n"
    "                             x along each curve of the plot); a value given twice\n"
    "                             (8,8 or 8,8.0) is refused\n"
    "  --csv OUT.csv              output table (required; written atomically)\n"
    "  --append                   add rows to an existing CSV whose first line is this\n"
    "                             run's header (else refused; default: overwrite)\n"
    "  --plot OUT.png|OUT.svg     log-log plot of time against error (default: none; the\n"
    "                             same as strahl plot OUT.csv afterwards, see its --help)\n"
    "  --baseline M.P=V,...       mark this setting in the plot, e.g. the brute-force one\n"
    "                             (default: none)\n"
    "  --frames F                 timed frames per setting, 1..10000 (default 10)\n"
    "  --warmup W                 untimed frames first, 0..10000 (default 2)\n"
    "  --metric rmse|relmse|scaled_rmse|max_abs   error column (default rmse)\n"
    "  --budget-error X           also print the cheapest setting with error <= X (default: off)\n"
    "  --mode recompute|steady    recompute: redo cached passes every frame (default);\n"
    "                             steady: time a static scene\n"
    "  --set MODULE.PARAM=VALUE   fixed parameter for every setting (repeatable)\n"
    "  --size WxH                 render size (default: the scene's; must match REF)\n"
    "  --filter box|point         pixel filter (default: REF's strahl.filter header attribute,\n"
    "                             point without one); a different one is used with a warning\n"
    "  --allow-outside-assets     let glTF buffer/image URIs and VDB files leave their folder\n"
    "                             (default: refused)\n" ST_CMD_SCENE_HELP
    "  --shard I/N                run only settings I-1, I-1+N, I-1+2N, ... of the sweep\n"
    "                             (default 1/1: all); only shard 1 writes the CSV header,\n"
    "                             so `cat` of shards 1..N in order is the whole table\n"
    "  -h, --help                 this text\n"
    "example:\n"
    "  strahl bench scenes/godrays_window.json --reference ref.exr --size 128x128 \\\n"
    "      --sweep toth.samples=16,64,256 --sweep toth.interleave=1,2 --csv toth.csv --plot "
    "toth.png\n";

// Whether the last value of sw equals an earlier one, as text or as a number
// ("8" and "8.0"): the same setting would be rendered twice.
static bool repeated_value(const sweep *sw) {
    const char *last = sw->values[sw->num_values - 1];
    char *e1, *e2;
    double x = strtod(last, &e1);
    for (int k = 0; k < sw->num_values - 1; k++) {
        double y = strtod(sw->values[k], &e2);
        if (!strcmp(sw->values[k], last) ||
            (e1 != last && !*e1 && e2 != sw->values[k] && !*e2 && x == y))
            return true;
    }
    return false;
}

static bool parse_sweep(const char *s, sweep *sw, st_err *err) {
    memset(sw, 0, sizeof *sw);
    const char *dot = strchr(s, '.'), *eq = strchr(s, '=');
    if (!dot || !eq || dot > eq || dot == s || eq == dot + 1 || !eq[1])
        return st_fail(err, ST_ERR_INPUT, "--sweep %s: expected MODULE.PARAM=v1,v2,...", s);
    snprintf(sw->module, sizeof sw->module, "%.*s", (int)(dot - s), s);
    snprintf(sw->param, sizeof sw->param, "%.*s", (int)(eq - dot - 1), dot + 1);
    for (const char *p = eq + 1; *p;) {
        const char *c = strchr(p, ',');
        size_t n = c ? (size_t)(c - p) : strlen(p);
        if (!n || n >= ST_NAME_MAX || sw->num_values == MAX_VALUES)
            return st_fail(err, ST_ERR_INPUT, "--sweep %s: empty or too many values (max %d)", s,
                           MAX_VALUES);
        snprintf(sw->values[sw->num_values++], ST_NAME_MAX, "%.*s", (int)n, p);
        p = c ? c + 1 : p + n;
        if (repeated_value(sw))
            return st_fail(err, ST_ERR_INPUT,
                           "--sweep %s: value '%s' is given twice (each setting runs once)", s,
                           sw->values[sw->num_values - 1]);
    }
    return true;
}

// debiased: with the reference's own variance removed (equal to the raw value
// when the reference has no standard-error channels; max_abs has no such form).
static double error_of(const st_metrics *m, const char *metric, bool debiased) {
    if (!strcmp(metric, "relmse")) return debiased ? m->relmse_debiased[3] : m->relmse[3];
    if (!strcmp(metric, "scaled_rmse"))
        return debiased ? m->scaled_rmse_debiased[3] : m->scaled_rmse[3];
    if (!strcmp(metric, "max_abs")) return m->max_abs[3];
    return debiased ? m->rmse_debiased[3] : m->rmse[3];
}

// Renders one setting; fills r. The scene has the setting applied already.
static bool run_one(const st_scene *scene, const st_image *ref, const st_image *ref_se, int frames,
                    int warmup, bool recompute, const char *metric, const sweep *sweeps,
                    int nsweeps, row *r, st_err *err) {
    st_world_opts opts = {.timing = true, .filter = scene->filter};
    st_world *w = st_world_create(scene, &opts, err);
    if (!w) return false;
    float *ft = calloc((size_t)frames, sizeof *ft);
    st_image img = {0};
    bool ok = ft != NULL;
    int timed = 0;
    for (int f = 0; ok && f < warmup + frames; f++) {
        if (f == warmup) st_world_reset_samples(w);
        // recompute: as if the lights moved every frame, so cached passes
        // (shadow maps, the atlas G-buffer and gather) are redone and the time
        // is the technique's per-frame cost under dynamic lighting.
        if (recompute) st_world_invalidate(w, ST_CHANGE_LIGHTS | ST_CHANGE_PARAMS);
        double t0 = st_now_ms();
        ok = st_world_frame(w, err);
        glFinish();
        if (f >= warmup) ft[timed++] = (float)(st_now_ms() - t0);
    }
    // A still is a converged image: the error is measured once every
    // progressive module has converged (frames past the timed ones).
    st_progress pr = {0};
    long extra = 0;
    while (ok && st_world_progress(w, &pr) && !pr.converged && extra < 2000) {
        ok = st_world_frame(w, err);
        extra++;
    }
    // The box filter's accumulation always takes frames; say so only when a
    // progressive module needed more.
    if (ok && extra > (long)st_world_accumulated(w, NULL))
        fprintf(stderr,
                "strahl bench: %s: %ld more frame(s) to converge, estimated remaining relative "
                "error %.4g\n",
                r->setting, extra, pr.error);
    ok = ok && st_world_read(w, &img, err) && st_image_compare_noisy(&img, ref, ref_se, &r->m, err);
    if (ok) {
        r->frame_ms = st_median_f(ft, timed);
        r->error = error_of(&r->m, metric, true);
        r->error_raw = error_of(&r->m, metric, false);
        // Per-module pass time: medians over the runs of each swept module's passes.
        r->module_gpu_ms = r->module_cpu_ms = 0;
        for (int i = 0; i < st_world_num_pass_stats(w); i++) {
            const st_pass_stats *s = st_world_pass_stats(w, i);
            bool swept = false;
            for (int k = 0; k < nsweeps; k++)
                swept |= !strcmp(s->module, sweeps[k].module);
            if (!swept || s->num_samples == 0) continue;
            double g = st_median_f(s->gpu_ms, s->num_samples);
            r->module_gpu_ms += g;
            size_t l = strlen(r->passes);
            snprintf(r->passes + l, sizeof r->passes - l, "%s%.40s=%.3f", l ? ";" : "", s->pass, g);
            r->module_cpu_ms += st_median_f(s->cpu_ms, s->num_samples);
        }
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        r->peak_rss_kb = ru.ru_maxrss;
        r->gpu_bytes = st_world_memory_bytes(w);
        if (st_image_count_nonfinite(&img))
            ok = st_fail(err, ST_ERR_RUNTIME, "%s: non-finite output", r->setting);
    }
    st_image_free(&img);
    free(ft);
    st_world_destroy(w);
    return ok;
}

static int cmp_time(const void *a, const void *b) {
    const row *x = *(row *const *)a, *y = *(row *const *)b;
    return (x->frame_ms > y->frame_ms) - (x->frame_ms < y->frame_ms);
}

// The command line.
typedef struct bench_args {
    const char *scene_path, *ref_path, *csv, *plot, *metric, *baseline, *filter_arg;
    char *sets[MAX_SETS];
    sweep sweeps[MAX_SWEEPS];
    int nsets, nsweeps, width, height;
    long frames, warmup, shard_i, shard_n;
    double budget;
    bool append, recompute;
} bench_args;

static const bench_args bench_defaults = {
    .metric = "rmse", .frames = 10, .warmup = 2, .budget = -1, .recompute = true};

// Options that take a value checked as a number or a word: argv[*i] is the
// option, v its value. Returns false with err set; *known says whether the
// option is one of these.
static bool parse_checked(bench_args *b, const char *a, const char *v, bool *known, st_err *err) {
    *known = true;
    if (!strcmp(a, "--mode")) {
        if (strcmp(v, "recompute") && strcmp(v, "steady"))
            return st_fail(err, ST_ERR_INPUT, "--mode %s: expected recompute or steady", v);
        b->recompute = !strcmp(v, "recompute");
    } else if (!strcmp(a, "--metric")) {
        b->metric = v;
        if (strcmp(v, "rmse") && strcmp(v, "relmse") && strcmp(v, "scaled_rmse") &&
            strcmp(v, "max_abs"))
            return st_fail(err, ST_ERR_INPUT,
                           "--metric %s: expected rmse, relmse, scaled_rmse or max_abs", v);
    } else if (!strcmp(a, "--filter")) {
        st_pixel_filter f;
        if (!st_filter_parse(v, &f))
            return st_fail(err, ST_ERR_INPUT, "--filter %s: expected box or point", v);
        b->filter_arg = v;
    } else if (!strcmp(a, "--size")) {
        if (!st_parse_size(v, &b->width, &b->height))
            return st_fail(err, ST_ERR_INPUT, "--size %s: expected WxH", v);
    } else if (!strcmp(a, "--frames")) {
        if (!st_parse_int(v, 1, 10000, &b->frames))
            return st_fail(err, ST_ERR_INPUT, "--frames %s: expected 1..10000", v);
    } else if (!strcmp(a, "--warmup")) {
        if (!st_parse_int(v, 0, 10000, &b->warmup))
            return st_fail(err, ST_ERR_INPUT, "--warmup %s: expected 0..10000", v);
    } else if (!strcmp(a, "--shard")) {
        const char *slash = strchr(v, '/');
        char num[32];
        snprintf(num, sizeof num, "%.*s", slash ? (int)(slash - v) : 0, v);
        if (!slash || !st_parse_int(slash + 1, 1, 100000, &b->shard_n) ||
            !st_parse_int(num, 1, b->shard_n, &b->shard_i))
            return st_fail(err, ST_ERR_INPUT, "--shard %s: expected I/N with 1 <= I <= N", v);
    } else if (!strcmp(a, "--budget-error")) {
        char *e;
        b->budget = strtod(v, &e);
        if (*e || !isfinite(b->budget) || b->budget < 0)
            return st_fail(err, ST_ERR_INPUT, "--budget-error %s: expected a non-negative number",
                           v);
    } else {
        *known = false;
    }
    return true;
}

// --sweep and --set (repeatable).
static bool parse_repeated(bench_args *b, const char *a, const char *v, bool *known, st_err *err) {
    *known = true;
    if (!strcmp(a, "--sweep")) {
        if (b->nsweeps == MAX_SWEEPS)
            return st_fail(err, ST_ERR_INPUT, "at most %d --sweep", MAX_SWEEPS);
        if (!parse_sweep(v, &b->sweeps[b->nsweeps++], err)) return false;
        const sweep *last = &b->sweeps[b->nsweeps - 1];
        for (int k = 0; k < b->nsweeps - 1; k++)
            if (!strcmp(b->sweeps[k].module, last->module) &&
                !strcmp(b->sweeps[k].param, last->param))
                return st_fail(err, ST_ERR_INPUT, "--sweep %s: %s.%s is swept twice", v,
                               b->sweeps[k].module, b->sweeps[k].param);
    } else if (!strcmp(a, "--set")) {
        if (b->nsets == MAX_SETS) return st_fail(err, ST_ERR_INPUT, "too many --set");
        b->sets[b->nsets++] = (char *)v;
    } else {
        *known = false;
    }
    return true;
}

// Fills b from argv; *help: -h was given (the text is printed).
static bool parse_args(bench_args *b, int argc, char **argv, bool *help, st_err *err) {
    *help = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool nx = i + 1 < argc, known = false;
        const char **path = !strcmp(a, "--reference")  ? &b->ref_path
                            : !strcmp(a, "--csv")      ? &b->csv
                            : !strcmp(a, "--plot")     ? &b->plot
                            : !strcmp(a, "--baseline") ? &b->baseline
                                                       : NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(help_text, stdout);
            *help = true;
            return true;
        } else if (path && nx) {
            *path = argv[++i];
        } else if (!strcmp(a, "--append")) {
            b->append = true;
        } else if (nx && (!parse_checked(b, a, argv[i + 1], &known, err) ||
                          (!known && !parse_repeated(b, a, argv[i + 1], &known, err)) ||
                          (!known && !st_cmd_scene_value(a, argv[i + 1], &known, err)))) {
            return false;
        } else if (known) {
            i++;
        } else if (st_cmd_scene_option(a)) {
        } else if (a[0] == '-' || b->scene_path) {
            return st_fail(err, ST_ERR_INPUT, "unexpected argument '%s'", a);
        } else {
            b->scene_path = a;
        }
    }
    return true;
}

// What the arguments must satisfy before any work: the required ones, no
// parameter both set and swept, outputs that are not inputs.
static bool check_args(const bench_args *b, st_err *err) {
    if (!b->scene_path || !b->ref_path || !b->csv || !b->nsweeps)
        return st_fail(err, ST_ERR_INPUT,
                       "usage: strahl bench SCENE.json --reference REF.exr --sweep "
                       "MODULE.PARAM=v1,v2,... "
                       "--csv OUT.csv [--plot OUT.png|svg] [--frames F] [--warmup W] [--metric M] "
                       "[--budget-error X] [--append] [--mode recompute|steady]");
    for (int i = 0; i < b->nsets; i++)
        for (int k = 0; k < b->nsweeps; k++) {
            char mp[2 * ST_NAME_MAX + 2];
            snprintf(mp, sizeof mp, "%s.%s=", b->sweeps[k].module, b->sweeps[k].param);
            if (!strncmp(b->sets[i], mp, strlen(mp)))
                return st_fail(err, ST_ERR_INPUT, "--set %s: %s.%s is also swept", b->sets[i],
                               b->sweeps[k].module, b->sweeps[k].param);
        }
    static const char *const csv_ext[] = {"csv", NULL}, *const plot_ext[] = {"png", "svg", NULL};
    const char *inputs[] = {b->scene_path, b->ref_path, NULL, NULL};
    return st_check_output("--csv", b->csv, csv_ext, inputs, err) &&
           (!b->plot ||
            (inputs[2] = b->csv, st_check_output("--plot", b->plot, plot_ext, inputs, err))) &&
           st_plot_check_baseline(b->baseline, err);
}

// --append: the rows so far (NULL without a file), their header checked.
static bool read_old_csv(const bench_args *b, const char *header, char **old, size_t *len,
                         st_err *err) {
    *old = NULL;
    *len = 0;
    if (!b->append || access(b->csv, F_OK) != 0) return true;
    *old = st_read_input(b->csv, ST_CAP_TEXT, "CSV file", len, err);
    if (!*old) return false;
    if (*len == 0) { // an empty file: as a new one, so it gets the header
        free(*old);
        *old = NULL;
        return true;
    }
    // The whole first line must be this run's header: a foreign CSV (or a
    // rows-only shard) would get rows its columns do not describe.
    size_t l1 = strcspn(*old, "\r\n");
    if (l1 != strlen(header) || strncmp(*old, header, l1)) {
        bool ours = !strncmp(*old, "scene,", 6);
        // The file's text reaches the terminal: control characters become '?'.
        char line[121];
        size_t k = 0;
        for (; k < l1 && k + 1 < sizeof line; k++)
            line[k] = (unsigned char)(*old)[k] < 0x20 || (*old)[k] == 0x7f ? '?' : (*old)[k];
        line[k] = 0;
        st_fail(err, ST_ERR_INPUT,
                "--append %s: header differs from this run's: its first line is '%s%s'; append "
                "to a CSV that strahl bench wrote%s",
                b->csv, line, l1 > k ? "..." : "",
                ours ? " with the same --metric and strahl version" : "");
        free(*old);
        *old = NULL;
        return false;
    }
    return true;
}

// The reference, its standard error and metadata; the pixel filter to
// render with (the reference's unless told otherwise, with a warning).
static bool read_reference(const bench_args *b, st_image *ref, st_image *ref_se, st_exr_meta *meta,
                           st_pixel_filter *filter, st_err *err) {
    if (!st_image_read_exr(b->ref_path, ref, err) ||
        !st_image_read_exr_stderr(b->ref_path, ref_se, err) ||
        !st_image_read_exr_meta(b->ref_path, meta, err)) {
        err->kind = ST_ERR_INPUT;
        return false;
    }
    *filter = ST_FILTER_POINT;
    st_filter_parse(st_exr_filter(meta), filter);
    if (b->filter_arg && strcmp(b->filter_arg, st_exr_filter(meta)))
        fprintf(stderr,
                "strahl bench: warning: --filter %s, but %s was made with the %s filter%s: the "
                "error includes the filters' difference at edges\n",
                b->filter_arg, b->ref_path, st_exr_filter(meta),
                meta->filter[0] ? "" : " (no strahl.filter attribute)");
    if (b->filter_arg) st_filter_parse(b->filter_arg, filter);
    return true;
}

// Setting idx of the sweep: its assignments (after the --set ones) in all,
// and r's setting, curve and x.
static int setting_of(const bench_args *b, int idx, char assign[][256], char **all, row *r) {
    int n = 0, rest = idx;
    for (int s = 0; s < b->nsets; s++)
        all[n++] = b->sets[s];
    for (int k = 0; k < b->nsweeps; k++) {
        const sweep *sw = &b->sweeps[k];
        int v = rest % sw->num_values;
        rest /= sw->num_values;
        snprintf(assign[k], 256, "%.63s.%.63s=%.63s", sw->module, sw->param, sw->values[v]);
        all[n++] = assign[k];
        size_t l = strlen(r->setting);
        snprintf(r->setting + l, sizeof r->setting - l, "%s%s", l ? " " : "", assign[k]);
        if (k == 0) {
            char *e;
            r->x = strtod(sw->values[v], &e);
            if (*e) r->x = v;
        } else {
            l = strlen(r->curve);
            snprintf(r->curve + l, sizeof r->curve - l, " %s", assign[k]);
        }
    }
    char curve[sizeof r->curve];
    snprintf(curve, sizeof curve, "%.63s%.190s", b->sweeps[0].module, r->curve);
    memcpy(r->curve, curve, sizeof curve);
    return n;
}

// Renders every setting of this shard into rows[0, *done), on `shared` (a
// caller's context, current) or a context of its own.
static bool run_settings(const bench_args *b, const st_image *ref, const st_image *ref_se,
                         st_pixel_filter filter, row *rows, int total, int *done,
                         st_progress_bar *bar, st_context *shared, st_err *err) {
    st_context *ctx = shared; // NULL: its own, made when first needed
    bool ok = true;
    for (int idx = 0; idx < total && ok; idx++) {
        // --shard I/N: settings I-1, I-1+N, ... (round robin, so shards of a
        // sweep ordered by cost get similar work).
        if (b->shard_n > 1 && idx % b->shard_n != b->shard_i - 1) continue;
        st_scene scene = {0};
        char *all[MAX_SETS + MAX_SWEEPS];
        char assign[MAX_SWEEPS][256];
        row *r = &rows[*done];
        int n = setting_of(b, idx, assign, all, r);
        if (!st_load_scene_with(b->scene_path, all, n, b->width, b->height, &scene, err)) {
            ok = false;
            break;
        }
        scene.filter = filter;
        // Only the loaded scene knows its glTF, buffer and VDB files.
        if (!st_scene_check_output(&scene, "--csv", b->csv, err) ||
            (b->plot && !st_scene_check_output(&scene, "--plot", b->plot, err)))
            ok = false;
        else if (scene.width != ref->width || scene.height != ref->height)
            ok = st_fail(err, ST_ERR_INPUT, "%s is %dx%d, the render is %dx%d (use --size)",
                         b->ref_path, ref->width, ref->height, scene.width, scene.height);
        else if (!ctx && !(ctx = st_context_create_headless(err)))
            ok = false;
        if (ok) {
            st_progress_update(bar, *done, r->setting);
            ok = run_one(&scene, ref, ref_se, (int)b->frames, (int)b->warmup, b->recompute,
                         b->metric, b->sweeps, b->nsweeps, r, err);
        }
        st_scene_free(&scene);
        if (!ok) break;
        r->noisy_ref = st_metrics_noise_dominates(&r->m); // one warning at the end
        (*done)++;
    }
    if (ctx != shared) st_context_destroy(ctx);
    return ok;
}

// One warning for the run, not one per row: which settings' errors the
// reference's noise cannot resolve (ref_noise_rms > debiased rmse / 3; the
// CSV's ref_noise_warning column flags them) and the spp that would resolve
// them all (the standard error falls as 1/sqrt(spp)).
static void warn_noisy_rows(const char *ref_path, int spp, const row *rows, int done) {
    int n = 0, listed = 0;
    double want = 0, noise = 0;
    bool zero = false;
    for (int i = 0; i < done; i++) {
        if (!rows[i].noisy_ref) continue;
        n++;
        double e = rows[i].m.rmse_debiased[3], s = rows[i].m.ref_noise_rms[3];
        noise = s;
        if (e > 0)
            want = fmax(want, ceil(spp * (3 * s / e) * (3 * s / e)));
        else
            zero = true;
    }
    if (!n) return;
    fprintf(stderr,
            "strahl bench: warning: %s: the reference's noise (rms standard error %.3g) is more "
            "than a third of the error of %d of %d settings (ref_noise_warning = 1 in the CSV): ",
            ref_path, noise, n, done);
    for (int i = 0; i < done; i++) {
        if (!rows[i].noisy_ref) continue;
        if (listed == 8) {
            fprintf(stderr, "; and %d more", n - listed);
            break;
        }
        fprintf(stderr, "%s%s", listed++ ? "; " : "", rows[i].setting);
    }
    if (spp > 0 && want > 0)
        fprintf(stderr, "; resolving them needs a reference of at least %.0f spp (it has %d)%s",
                fmin(want, 1e9), spp, zero ? " and more for the rows of debiased error 0" : "");
    else if (zero)
        fprintf(stderr, "; a debiased error of 0 means the error is below what it resolves");
    fputc('\n', stderr);
}

// The CSV's rows (the columns of bench_header).
static void write_rows(FILE *f, const bench_args *b, const row *rows, int done) {
    for (int i = 0; i < done; i++) {
        const row *r = &rows[i];
        fprintf(f,
                "%s,%s,%s,%g,%ld,%.4f,%.4f,%.4f,%.9g,%.9g,%.9g,%.6g,%.9g,%.9g,%.9g,%ld,%zu,%s,%"
                ".9g,%.9g,%d\n",
                b->scene_path, r->setting, r->curve, r->x, b->frames, r->frame_ms, r->module_gpu_ms,
                r->module_cpu_ms, r->error, r->m.rmse[3], r->m.relmse[3],
                isfinite(r->m.psnr[3]) ? r->m.psnr[3] : 999.0, r->m.max_abs[3], r->m.scale,
                r->m.scaled_rmse[3], r->peak_rss_kb, r->gpu_bytes, r->passes, r->error_raw,
                r->m.ref_noise_rms[3], r->noisy_ref ? 1 : 0);
    }
}

// The CSV's header line (without the newline).
static void bench_header(const char *metric, char *out, size_t n) {
    snprintf(out, n,
             "scene,setting,curve,x,frames,frame_ms_median,module_gpu_ms_median,module_cpu_"
             "ms_median,error_%s,rmse,relmse,psnr,max_abs,scale,scaled_rmse,peak_rss_kb,gpu_bytes,"
             "pass_gpu_ms,error_raw,ref_noise_rms,ref_noise_warning",
             metric);
}

// The CSV, atomically; --append adds rows to an existing file.
static bool write_csv(const bench_args *b, const char *header, const char *old, size_t old_len,
                      const row *rows, int done, st_err *err) {
    st_outfile o;
    FILE *f = st_out_begin(&o, b->csv, err) ? st_out_stream(&o, err) : NULL;
    if (!f) {
        st_out_abort(&o);
        return false;
    }
    if (old) {
        fwrite(old, 1, old_len, f);
        if (old_len && old[old_len - 1] != '\n') fputc('\n', f);
    } else if (b->shard_i <= 1) { // shards 2..N: rows only, so `cat` of all shards is one CSV
        fprintf(f, "%s\n", header);
    }
    write_rows(f, b, rows, done);
    return st_out_commit(&o, err);
}

// Every setting by time, the Pareto front (settings no faster setting beats
// in error) and, with --budget-error, the cheapest setting within it.
static void print_front(const bench_args *b, row *rows, int done) {
    const char *metric = b->metric;
    row *sorted[MAX_ROWS];
    for (int i = 0; i < done; i++)
        sorted[i] = &rows[i];
    qsort(sorted, (size_t)done, sizeof sorted[0], cmp_time);
    printf("%-48s %12s %14s %14s %14s\n", "setting", "frame ms", "module gpu ms", metric, "raw");
    for (int i = 0; i < done; i++)
        printf("%-48s %12.3f %14.3f %14.6g %14.6g%s\n", sorted[i]->setting, sorted[i]->frame_ms,
               sorted[i]->module_gpu_ms, sorted[i]->error, sorted[i]->error_raw,
               sorted[i]->noisy_ref ? "  (reference too noisy)" : "");
    printf("Pareto front (faster settings with a lower %s):\n", metric);
    double best = INFINITY;
    for (int i = 0; i < done; i++) {
        if (sorted[i]->error >= best) continue;
        best = sorted[i]->error;
        printf("  %s: %.3f ms, %s %.6g\n", sorted[i]->setting, sorted[i]->frame_ms, metric,
               sorted[i]->error);
    }
    if (b->budget < 0) return;
    const row *pick = NULL;
    for (int i = 0; i < done && !pick; i++)
        if (sorted[i]->error <= b->budget) pick = sorted[i];
    if (pick)
        printf("cheapest setting with %s <= %g: %s (%.3f ms, %s %.6g)\n", metric, b->budget,
               pick->setting, pick->frame_ms, metric, pick->error);
    else
        printf("no setting reaches %s <= %g\n", metric, b->budget);
}

// Rows for every setting of the sweep (*total of them).
static row *alloc_rows(const bench_args *b, int *total, st_err *err) {
    *total = 1;
    for (int k = 0; k < b->nsweeps; k++)
        *total *= b->sweeps[k].num_values;
    if (*total > MAX_ROWS) {
        st_fail(err, ST_ERR_INPUT, "%d settings: at most %d", *total, MAX_ROWS);
        return NULL;
    }
    row *rows = calloc((size_t)*total, sizeof *rows);
    if (!rows) st_fail(err, ST_ERR_RUNTIME, "out of memory");
    return rows;
}

// Everything after the arguments: render, write, report.
static bool bench(const bench_args *b, const char *header, st_progress_bar *bar, st_err *err) {
    char *old = NULL;
    size_t old_len = 0;
    if (!read_old_csv(b, header, &old, &old_len, err)) return false;
    st_image ref = {0}, ref_se = {0};
    st_exr_meta ref_meta = {0};
    st_pixel_filter filter;
    row *rows = NULL;
    int total = 0, done = 0;
    bool ok = read_reference(b, &ref, &ref_se, &ref_meta, &filter, err) &&
              (rows = alloc_rows(b, &total, err)) != NULL;
    if (ok) {
        // A shard runs about total/N settings (shard I: ceil((total - I + 1) / N)).
        st_progress_begin(bar, "bench", "settings",
                          b->shard_n > 1 ? (int)((total - b->shard_i + b->shard_n) / b->shard_n)
                                         : total);
    }
    ok = ok && run_settings(b, &ref, &ref_se, filter, rows, total, &done, bar, NULL, err);
    if (ok) {
        // Before anything goes to stdout, so the table does not run into the bar.
        char extra[64] = "";
        if (b->shard_n > 1) snprintf(extra, sizeof extra, "shard %ld/%ld", b->shard_i, b->shard_n);
        st_progress_end(bar, done, extra);
        bar->drawn = false;
        warn_noisy_rows(b->ref_path, ref_meta.spp, rows, done);
        ok = write_csv(b, header, old, old_len, rows, done, err);
    }
    if (ok) print_front(b, rows, done);
    ok = ok && (!b->plot || st_plot_csv(&b->csv, 1, b->plot, b->metric, b->baseline, NULL, err));
    st_image_free(&ref);
    st_image_free(&ref_se);
    free(rows);
    free(old);
    return ok;
}

int st_cmd_bench(int argc, char **argv) {
    bench_args b = bench_defaults;
    st_err err = {0};
    bool help;
    if (!parse_args(&b, argc, argv, &help, &err)) return st_report("bench", &err);
    if (help) return ST_EXIT_OK;
    if (!check_args(&b, &err)) return st_report("bench", &err);
    char header[1024];
    bench_header(b.metric, header, sizeof header);
    st_progress_bar bar = {0};
    if (bench(&b, header, &bar, &err)) return ST_EXIT_OK;
    if (bar.drawn) fputc('\n', stderr); // end the bar's line before the message
    return st_report("bench", &err);
}

char *st_bench_rows(int argc, char **argv, st_context *ctx, st_err *err) {
    bench_args b = bench_defaults;
    bool help;
    if (!parse_args(&b, argc, argv, &help, err)) return NULL;
    // Rows only: no CSV file is written, the name just passes check_args.
    if (!b.csv) b.csv = "rows.csv";
    st_image ref = {0}, ref_se = {0};
    st_exr_meta meta = {0};
    st_pixel_filter filter;
    st_progress_bar bar = {0}; // never drawn: the caller reports progress
    row *rows = NULL;
    int total = 0, done = 0;
    char *text = NULL, header[1024];
    size_t len = 0;
    bool ok = !help && check_args(&b, err) &&
              read_reference(&b, &ref, &ref_se, &meta, &filter, err) &&
              (rows = alloc_rows(&b, &total, err)) != NULL &&
              run_settings(&b, &ref, &ref_se, filter, rows, total, &done, &bar, ctx, err);
    FILE *f = ok ? open_memstream(&text, &len) : NULL;
    if (f) {
        bench_header(b.metric, header, sizeof header);
        fprintf(f, "%s\n", header);
        write_rows(f, &b, rows, done);
        fclose(f);
    } else if (ok) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
    }
    st_image_free(&ref);
    st_image_free(&ref_se);
    free(rows);
    return f ? text : NULL;
}
