// strahl bench: run time against error. For every combination of the swept
// parameter values, render warm-up + F frames in a fresh world, record the
// median frame time, the median GPU time of each module's passes (timer
// queries), peak memory, and the error of the last frame against a reference
// image. --mode recompute (default) redoes cached passes every frame so the
// time is the technique's whole cost; steady times what a static scene
// costs per frame. Writes CSV, prints the Pareto front, draws a log-log plot (gnuplot).
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
    "error_raw keeps the raw value, and a warning names the settings whose error the\n"
    "reference's noise cannot resolve (ref_noise_rms > debiased rmse / 3).\n"
    "  --reference REF.exr        reference image of the same size (required)\n"
    "  --sweep MODULE.PARAM=v,... values to sweep (required, up to 4; the first is the\n"
    "                             x along each curve of the plot)\n"
    "  --csv OUT.csv              output table (required; written atomically)\n"
    "  --append                   add rows to an existing CSV (default: overwrite)\n"
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
    "  --allow-outside-assets     let glTF buffer/image URIs leave the glTF file's folder\n"
    "                             (default: refused)\n"
    "  --shard I/N                run only settings I-1, I-1+N, I-1+2N, ... of the sweep\n"
    "                             (default 1/1: all); only shard 1 writes the CSV header,\n"
    "                             so `cat` of shards 1..N in order is the whole table\n"
    "  -h, --help                 this text\n"
    "example:\n"
    "  strahl bench scenes/godrays_window.json --reference ref.exr --size 128x128 \\\n"
    "      --sweep toth.samples=16,64,256 --sweep toth.interleave=1,2 --csv toth.csv --plot "
    "toth.png\n";

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

int st_cmd_bench(int argc, char **argv) {
    const char *scene_path = NULL, *ref_path = NULL, *csv = NULL, *plot = NULL, *metric = "rmse",
               *baseline = NULL;
    char *sets[MAX_SETS];
    sweep sweeps[MAX_SWEEPS];
    int nsets = 0, nsweeps = 0, width = 0, height = 0;
    long frames = 10, warmup = 2;
    double budget = -1;
    long shard_i = 0, shard_n = 0;
    bool append = false, recompute = true;
    const char *filter_arg = NULL;
    st_err err = {0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool nx = i + 1 < argc;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(help_text, stdout);
            return ST_EXIT_OK;
        } else if (!strcmp(a, "--reference") && nx)
            ref_path = argv[++i];
        else if (!strcmp(a, "--csv") && nx)
            csv = argv[++i];
        else if (!strcmp(a, "--plot") && nx)
            plot = argv[++i];
        else if (!strcmp(a, "--baseline") && nx)
            baseline = argv[++i];
        else if (!strcmp(a, "--append"))
            append = true;
        else if (!strcmp(a, "--mode") && nx) {
            const char *m = argv[++i];
            if (strcmp(m, "recompute") && strcmp(m, "steady"))
                return st_fail(&err, ST_ERR_INPUT, "--mode %s: expected recompute or steady", m),
                       st_report("bench", &err);
            recompute = !strcmp(m, "recompute");
        } else if (!strcmp(a, "--metric") && nx) {
            metric = argv[++i];
            if (strcmp(metric, "rmse") && strcmp(metric, "relmse") &&
                strcmp(metric, "scaled_rmse") && strcmp(metric, "max_abs"))
                return st_fail(&err, ST_ERR_INPUT,
                               "--metric %s: expected rmse, relmse, scaled_rmse or max_abs",
                               metric),
                       st_report("bench", &err);
        } else if (!strcmp(a, "--sweep") && nx) {
            if (nsweeps == MAX_SWEEPS)
                return st_fail(&err, ST_ERR_INPUT, "at most %d --sweep", MAX_SWEEPS),
                       st_report("bench", &err);
            if (!parse_sweep(argv[++i], &sweeps[nsweeps++], &err)) return st_report("bench", &err);
            for (int k = 0; k < nsweeps - 1; k++)
                if (!strcmp(sweeps[k].module, sweeps[nsweeps - 1].module) &&
                    !strcmp(sweeps[k].param, sweeps[nsweeps - 1].param))
                    return st_fail(&err, ST_ERR_INPUT, "--sweep %s: %s.%s is swept twice", argv[i],
                                   sweeps[k].module, sweeps[k].param),
                           st_report("bench", &err);
        } else if (!strcmp(a, "--set") && nx) {
            if (nsets == MAX_SETS)
                return st_fail(&err, ST_ERR_INPUT, "too many --set"), st_report("bench", &err);
            sets[nsets++] = argv[++i];
        } else if (!strcmp(a, "--filter") && nx) {
            st_pixel_filter f;
            if (!st_filter_parse(argv[++i], &f))
                return st_fail(&err, ST_ERR_INPUT, "--filter %s: expected box or point", argv[i]),
                       st_report("bench", &err);
            filter_arg = argv[i];
        } else if (!strcmp(a, "--size") && nx) {
            if (!st_parse_size(argv[++i], &width, &height))
                return st_fail(&err, ST_ERR_INPUT, "--size %s: expected WxH", argv[i]),
                       st_report("bench", &err);
        } else if (!strcmp(a, "--frames") && nx) {
            if (!st_parse_int(argv[++i], 1, 10000, &frames))
                return st_fail(&err, ST_ERR_INPUT, "--frames %s: expected 1..10000", argv[i]),
                       st_report("bench", &err);
        } else if (!strcmp(a, "--warmup") && nx) {
            if (!st_parse_int(argv[++i], 0, 10000, &warmup))
                return st_fail(&err, ST_ERR_INPUT, "--warmup %s: expected 0..10000", argv[i]),
                       st_report("bench", &err);
        } else if (!strcmp(a, "--shard") && nx) {
            const char *v = argv[++i], *slash = strchr(v, '/');
            char num[32];
            snprintf(num, sizeof num, "%.*s", slash ? (int)(slash - v) : 0, v);
            if (!slash || !st_parse_int(slash + 1, 1, 100000, &shard_n) ||
                !st_parse_int(num, 1, shard_n, &shard_i))
                return st_fail(&err, ST_ERR_INPUT, "--shard %s: expected I/N with 1 <= I <= N", v),
                       st_report("bench", &err);
        } else if (!strcmp(a, "--budget-error") && nx) {
            char *e;
            budget = strtod(argv[++i], &e);
            if (*e || !isfinite(budget) || budget < 0)
                return st_fail(&err, ST_ERR_INPUT,
                               "--budget-error %s: expected a non-negative number", argv[i]),
                       st_report("bench", &err);
        } else if (st_cmd_scene_option(a)) {
        } else if (a[0] == '-' || scene_path) {
            return st_fail(&err, ST_ERR_INPUT, "unexpected argument '%s'", a),
                   st_report("bench", &err);
        } else {
            scene_path = a;
        }
    }
    if (!scene_path || !ref_path || !csv || !nsweeps)
        return st_fail(&err, ST_ERR_INPUT,
                       "usage: strahl bench SCENE.json --reference REF.exr --sweep "
                       "MODULE.PARAM=v1,v2,... "
                       "--csv OUT.csv [--plot OUT.png|svg] [--frames F] [--warmup W] [--metric M] "
                       "[--budget-error X] [--append] [--mode recompute|steady]"),
               st_report("bench", &err);
    for (int i = 0; i < nsets; i++)
        for (int k = 0; k < nsweeps; k++) {
            char mp[2 * ST_NAME_MAX + 2];
            snprintf(mp, sizeof mp, "%s.%s=", sweeps[k].module, sweeps[k].param);
            if (!strncmp(sets[i], mp, strlen(mp)))
                return st_fail(&err, ST_ERR_INPUT, "--set %s: %s.%s is also swept", sets[i],
                               sweeps[k].module, sweeps[k].param),
                       st_report("bench", &err);
        }
    // Outputs are checked before any work, and never one of the inputs.
    static const char *const csv_ext[] = {"csv", NULL}, *const plot_ext[] = {"png", "svg", NULL};
    const char *inputs[] = {scene_path, ref_path, NULL, NULL};
    if (!st_check_output("--csv", csv, csv_ext, inputs, &err) ||
        (plot && (inputs[2] = csv, !st_check_output("--plot", plot, plot_ext, inputs, &err))) ||
        !st_plot_check_baseline(baseline, &err))
        return st_report("bench", &err);
    char header[1024];
    snprintf(header, sizeof header,
             "scene,setting,curve,x,frames,frame_ms_median,module_gpu_ms_median,module_cpu_"
             "ms_median,error_%s,rmse,relmse,psnr,max_abs,scale,scaled_rmse,peak_rss_kb,gpu_bytes,"
             "pass_gpu_ms,error_raw,ref_noise_rms,ref_noise_warning",
             metric);
    // --append: the rows so far, read (and their header checked) now.
    char *old = NULL;
    size_t old_len = 0;
    if (append && access(csv, F_OK) == 0) {
        old = st_read_input(csv, ST_CAP_TEXT, "CSV file", &old_len, &err);
        if (!old) return st_report("bench", &err);
        size_t l1 = strcspn(old, "\r\n");
        if (!strncmp(old, "scene,", 6) && (l1 != strlen(header) || strncmp(old, header, l1))) {
            st_fail(&err, ST_ERR_INPUT,
                    "--append %s: its header differs from this run's (%.*s); append to a CSV of "
                    "the same --metric and strahl version",
                    csv, (int)(l1 < 200 ? l1 : 200), old);
            free(old);
            return st_report("bench", &err);
        }
    }
    st_image ref = {0}, ref_se = {0};
    st_exr_meta ref_meta = {0};
    if (!st_image_read_exr(ref_path, &ref, &err) ||
        !st_image_read_exr_stderr(ref_path, &ref_se, &err) ||
        !st_image_read_exr_meta(ref_path, &ref_meta, &err)) {
        err.kind = ST_ERR_INPUT;
        st_image_free(&ref);
        free(old);
        return st_report("bench", &err);
    }
    // Render with the reference's pixel filter unless told otherwise.
    st_pixel_filter filter = ST_FILTER_POINT;
    st_filter_parse(st_exr_filter(&ref_meta), &filter);
    if (filter_arg && strcmp(filter_arg, st_exr_filter(&ref_meta)))
        fprintf(stderr,
                "strahl bench: warning: --filter %s, but %s was made with the %s filter%s: the "
                "error includes the filters' difference at edges\n",
                filter_arg, ref_path, st_exr_filter(&ref_meta),
                ref_meta.filter[0] ? "" : " (no strahl.filter attribute)");
    if (filter_arg) st_filter_parse(filter_arg, &filter);
    // Validate the scene and every swept value before any rendering.
    int total = 1;
    for (int k = 0; k < nsweeps; k++)
        total *= sweeps[k].num_values;
    if (total > MAX_ROWS) {
        st_image_free(&ref);
        free(old);
        return st_fail(&err, ST_ERR_INPUT, "%d settings: at most %d", total, MAX_ROWS),
               st_report("bench", &err);
    }
    row *rows = calloc((size_t)total, sizeof *rows);
    st_context *ctx = NULL;
    int rc = 0, done = 0;
    st_progress_bar bar;
    // A shard runs about total/N settings (shard I: ceil((total - I + 1) / N)).
    st_progress_begin(&bar, "bench", "settings",
                      shard_n > 1 ? (int)((total - shard_i + shard_n) / shard_n) : total);
    if (!rows) {
        st_fail(&err, ST_ERR_RUNTIME, "out of memory");
        goto fail;
    }
    for (int idx = 0; idx < total; idx++) {
        st_scene scene = {0};
        char *all[MAX_SETS + MAX_SWEEPS];
        char assign[MAX_SWEEPS][256];
        int n = 0, rest = idx;
        for (int s = 0; s < nsets; s++)
            all[n++] = sets[s];
        // --shard I/N: settings I-1, I-1+N, ... (round robin, so shards of a
        // sweep ordered by cost get similar work).
        if (shard_n > 1 && idx % shard_n != shard_i - 1) continue;
        row *r = &rows[done];
        for (int k = 0; k < nsweeps; k++) {
            int v = rest % sweeps[k].num_values;
            rest /= sweeps[k].num_values;
            snprintf(assign[k], sizeof assign[k], "%.63s.%.63s=%.63s", sweeps[k].module,
                     sweeps[k].param, sweeps[k].values[v]);
            all[n++] = assign[k];
            size_t l = strlen(r->setting);
            snprintf(r->setting + l, sizeof r->setting - l, "%s%s", l ? " " : "", assign[k]);
            if (k == 0) {
                char *e;
                r->x = strtod(sweeps[k].values[v], &e);
                if (*e) r->x = v;
            } else {
                l = strlen(r->curve);
                snprintf(r->curve + l, sizeof r->curve - l, " %s", assign[k]);
            }
        }
        char curve[sizeof r->curve];
        snprintf(curve, sizeof curve, "%.63s%.190s", sweeps[0].module, r->curve);
        memcpy(r->curve, curve, sizeof curve);
        if (!st_load_scene_with(scene_path, all, n, width, height, &scene, &err)) goto fail;
        scene.filter = filter;
        if (scene.width != ref.width || scene.height != ref.height) {
            st_fail(&err, ST_ERR_INPUT, "%s is %dx%d, the render is %dx%d (use --size)", ref_path,
                    ref.width, ref.height, scene.width, scene.height);
            st_scene_free(&scene);
            goto fail;
        }
        if (!ctx && !(ctx = st_context_create_headless(&err))) {
            st_scene_free(&scene);
            goto fail;
        }
        st_progress_update(&bar, done, r->setting);
        bool ok = run_one(&scene, &ref, &ref_se, (int)frames, (int)warmup, recompute, metric,
                          sweeps, nsweeps, r, &err);
        st_scene_free(&scene);
        if (!ok) goto fail;
        r->noisy_ref = st_warn_reference_noise("bench", ref_path, &r->m, ref_meta.spp);
        done++;
    }
    {
        // Before anything goes to stdout, so the table does not run into the bar.
        char extra[64] = "";
        if (shard_n > 1) snprintf(extra, sizeof extra, "shard %ld/%ld", shard_i, shard_n);
        st_progress_end(&bar, done, extra);
        bar.drawn = false;
    }
    {
        // CSV (atomically; --append adds rows to an existing file).
        st_outfile o;
        FILE *f = st_out_begin(&o, csv, &err) ? st_out_stream(&o, &err) : NULL;
        if (!f) {
            st_out_abort(&o);
            goto fail;
        }
        if (old) {
            fwrite(old, 1, old_len, f);
            if (old_len && old[old_len - 1] != '\n') fputc('\n', f);
        } else if (shard_i <= 1) { // shards 2..N: rows only, so `cat` of all shards is one CSV
            fprintf(f, "%s\n", header);
        }
        for (int i = 0; i < done; i++) {
            row *r = &rows[i];
            fprintf(f,
                    "%s,%s,%s,%g,%ld,%.4f,%.4f,%.4f,%.9g,%.9g,%.9g,%.6g,%.9g,%.9g,%.9g,%ld,%zu,%s,%"
                    ".9g,%.9g,%d\n",
                    scene_path, r->setting, r->curve, r->x, frames, r->frame_ms, r->module_gpu_ms,
                    r->module_cpu_ms, r->error, r->m.rmse[3], r->m.relmse[3],
                    isfinite(r->m.psnr[3]) ? r->m.psnr[3] : 999.0, r->m.max_abs[3], r->m.scale,
                    r->m.scaled_rmse[3], r->peak_rss_kb, r->gpu_bytes, r->passes, r->error_raw,
                    r->m.ref_noise_rms[3], r->noisy_ref ? 1 : 0);
        }
        if (!st_out_commit(&o, &err)) goto fail;
    }
    {
        // Pareto front: settings no faster setting beats in error.
        row *sorted[MAX_ROWS];
        for (int i = 0; i < done; i++)
            sorted[i] = &rows[i];
        qsort(sorted, (size_t)done, sizeof sorted[0], cmp_time);
        printf("%-48s %12s %14s %14s %14s\n", "setting", "frame ms", "module gpu ms", metric,
               "raw");
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
        if (budget >= 0) {
            const row *pick = NULL;
            for (int i = 0; i < done && !pick; i++)
                if (sorted[i]->error <= budget) pick = sorted[i];
            if (pick)
                printf("cheapest setting with %s <= %g: %s (%.3f ms, %s %.6g)\n", metric, budget,
                       pick->setting, pick->frame_ms, metric, pick->error);
            else
                printf("no setting reaches %s <= %g\n", metric, budget);
        }
    }
    if (plot && !st_plot_csv(&csv, 1, plot, metric, baseline, NULL, &err)) goto fail;
    goto out;
fail:
    if (bar.drawn) fputc('\n', stderr); // end the bar's line before the message
    rc = st_report("bench", &err);
out:
    st_context_destroy(ctx);
    st_image_free(&ref);
    st_image_free(&ref_se);
    free(rows);
    free(old);
    return rc;
}
