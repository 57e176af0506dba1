// strahl compare A.exr B.exr [--json] [--heatmap OUT.png [--scale MAX]]
// Error metrics of A against the reference B. Output is printed only after
// everything (including the heat map) succeeded.
#include "cmd_common.h"
#include "false_colour.h"
#include "st_cmd.h"
#include "st_file.h"
#include "st_image.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char help_text[] =
    "usage: strahl compare A.exr B.exr [--json] [--heatmap OUT.png [--scale MAX]]\n"
    "Error of A against the reference B, per channel and over R,G,B: rmse, relmse\n"
    "((a-b)^2 / (b^2 + 0.01)), psnr (peak = max of B), max_abs, the scale s minimising\n"
    "|s A - B| and the rmse after scaling.\n"
    "When B has per-pixel standard error channels (stderr.R/G/B, as strahl reference\n"
    "writes), also the errors with B's own noise removed: rmse_debiased =\n"
    "sqrt(max(0, mean((a-b)^2 - s^2))), relmse_debiased and scaled_rmse_debiased alike,\n"
    "and ref_noise_rms = sqrt(mean(s^2)); a warning goes to stderr when ref_noise_rms\n"
    "exceeds a third of rmse_debiased (the reference is too noisy to resolve the error).\n"
    "A warning also goes to stderr when A and B were made with different pixel filters\n"
    "(the strahl.filter header attribute, box or point; a file without it counts as point,\n"
    "as strahl wrote them before it had the box filter).\n"
    "  --json             one JSON object instead of the table (default: text)\n"
    "  --heatmap OUT.png  |A - B| (mean over R,G,B) in false colour, black 0, blue 1/4,\n"
    "                     red 1/2, yellow 3/4, white the scale and above, with a colour\n"
    "                     bar and its values in 24 rows below (the image is padded to\n"
    "                     96 px wide); the scale is in the PNG's tEXt chunk strahl.scale\n"
    "                     (default: none)\n"
    "  --scale MAX        the difference drawn white, so heat maps of several images\n"
    "                     share one scale (default: the largest difference)\n"
    "  -h, --help         this text\n"
    "example:\n"
    "  strahl compare out/toth.exr ref.exr --heatmap out/diff.png\n";

static int fail(const st_err *err) {
    fprintf(stderr, "strahl compare: %s\n", err->msg);
    return st_err_exit_code(err);
}

static int bad_usage(const char *what, const char *arg) {
    fprintf(stderr,
            "strahl compare: %s '%s' (usage: strahl compare A.exr B.exr [--json] "
            "[--heatmap OUT.png [--scale MAX]])\n",
            what, arg);
    return ST_EXIT_INPUT;
}

// JSON has no infinities: a non-finite value (psnr of identical images) is null.
static void json_num(double v) {
    if (isfinite(v))
        printf("%.9g", v);
    else
        printf("null");
}

static void json_rgba(const char *key, const double v[4], bool last) {
    static const char *const k[4] = {"r", "g", "b", "all"};
    printf("\"%s\":{", key);
    for (int c = 0; c < 4; c++) {
        printf("\"%s\":", k[c]);
        json_num(v[c]);
        if (c < 3) putchar(',');
    }
    printf("}%s", last ? "" : ",");
}

static void print_json(const st_metrics *m, int w, int h) {
    putchar('{');
    json_rgba("rmse", m->rmse, false);
    json_rgba("relmse", m->relmse, false);
    json_rgba("psnr", m->psnr, false);
    json_rgba("max_abs", m->max_abs, false);
    printf("\"scale\":");
    json_num(m->scale);
    putchar(',');
    json_rgba("scaled_rmse", m->scaled_rmse, false);
    json_rgba("mean_a", m->mean_a, false);
    json_rgba("mean_b", m->mean_b, false);
    if (m->has_ref_noise) {
        json_rgba("rmse_debiased", m->rmse_debiased, false);
        json_rgba("relmse_debiased", m->relmse_debiased, false);
        json_rgba("scaled_rmse_debiased", m->scaled_rmse_debiased, false);
        json_rgba("ref_noise_rms", m->ref_noise_rms, false);
    }
    printf("\"reference_noise_warning\":%s,", st_metrics_noise_dominates(m) ? "true" : "false");
    printf("\"width\":%d,\"height\":%d}\n", w, h);
}

static void text_row(const char *name, const double v[4]) {
    printf("%-20s %16.9g %16.9g %16.9g %16.9g\n", name, v[0], v[1], v[2], v[3]);
}

static void print_text(const st_metrics *m, int w, int h, const char *a, const char *b) {
    printf("image        %s\nreference    %s\nsize         %dx%d\n", a, b, w, h);
    printf("%-20s %16s %16s %16s %16s\n", "metric", "R", "G", "B", "all");
    text_row("rmse", m->rmse);
    text_row("relmse", m->relmse);
    text_row("psnr", m->psnr); // printf writes "inf" for identical images
    text_row("max_abs", m->max_abs);
    text_row("scaled_rmse", m->scaled_rmse);
    text_row("mean_a", m->mean_a);
    text_row("mean_b", m->mean_b);
    printf("%-20s %16.9g\n", "scale", m->scale);
    if (!m->has_ref_noise) return;
    // Raw numbers above, the reference's own variance removed below.
    text_row("rmse_debiased", m->rmse_debiased);
    text_row("relmse_debiased", m->relmse_debiased);
    text_row("scaled_rmse_debiased", m->scaled_rmse_debiased);
    text_row("ref_noise_rms", m->ref_noise_rms);
}

// The mean over R,G,B of |A - B| (a grey image counts for all three), in
// false colour with its legend; scale <= 0: the largest difference.
static bool write_heatmap(const char *path, const st_image *a, const st_image *b, double scale,
                          st_err *err) {
    const size_t n = (size_t)a->width * a->height;
    double *d = malloc(n * sizeof *d);
    if (!d) return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    for (size_t i = 0; i < n; i++) {
        const float *pa = a->data + i * a->channels, *pb = b->data + i * b->channels;
        double s = 0;
        for (int c = 0; c < 3; c++)
            s += fabs((double)pa[a->channels >= 3 ? c : 0] - pb[b->channels >= 3 ? c : 0]);
        d[i] = s / 3;
    }
    st_false_colour fc = {.quantity = "mean over R,G,B of |A - B|", .scale = scale};
    // Identical images: a black map on the smallest scale rather than a division by 0.
    if (!(fc.scale > 0)) fc.scale = fmax(st_false_colour_max(d, n), 1e-12);
    bool ok = st_write_false_colour(path, d, a->width, a->height, &fc, err);
    free(d);
    return ok;
}

// --scale MAX: a positive finite number.
static bool parse_scale(const char *s, double *out) {
    char *e;
    *out = strtod(s, &e);
    return e != s && !*e && isfinite(*out) && *out > 0;
}

int st_cmd_compare(int argc, char **argv) {
    const char *files[3] = {NULL, NULL, NULL}, *heatmap = NULL;
    int nfiles = 0;
    bool json = false;
    double scale = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "--json")) {
            json = true;
        } else if (!strcmp(arg, "--heatmap")) {
            if (i + 1 >= argc) return bad_usage("missing file name after", arg);
            heatmap = argv[++i];
        } else if (!strncmp(arg, "--heatmap=", 10)) {
            heatmap = arg + 10;
        } else if (!strcmp(arg, "--scale")) {
            if (i + 1 >= argc) return bad_usage("missing value after", arg);
            if (!parse_scale(argv[++i], &scale))
                return bad_usage("--scale: expected a positive finite number, got", argv[i]);
        } else if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
            fputs(help_text, stdout);
            return ST_EXIT_OK;
        } else if (arg[0] == '-' && arg[1]) {
            return bad_usage("unknown option", arg);
        } else if (nfiles < 2) {
            files[nfiles++] = arg;
        } else {
            return bad_usage("unexpected argument", arg);
        }
    }
    if (nfiles < 2) {
        fprintf(stderr, "strahl compare: needs two images (usage: strahl compare A.exr B.exr "
                        "[--json] [--heatmap OUT.png [--scale MAX]])\n");
        return ST_EXIT_INPUT;
    }
    if (scale > 0 && !heatmap)
        return bad_usage("--scale is the heat map's; give --heatmap with", "--scale");
    st_err err = {0};
    static const char *const exts[] = {"png", NULL};
    if (heatmap && !st_check_output("--heatmap", heatmap, exts, files, &err)) return fail(&err);
    st_image a = {0}, b = {0}, bs = {0};
    st_exr_meta meta = {0}, meta_a = {0};
    st_metrics m;
    int rc = ST_EXIT_OK;
    if (!st_image_read_exr(files[0], &a, &err) || !st_image_read_exr(files[1], &b, &err) ||
        !st_image_read_exr_stderr(files[1], &bs, &err) ||
        !st_image_read_exr_meta(files[1], &meta, &err) ||
        !st_image_read_exr_meta(files[0], &meta_a, &err)) {
        rc = fail(&err);
    } else if (!st_image_compare_noisy(&a, &b, &bs, &m, &err)) {
        // Name both files: the message itself only knows "image"/"reference".
        st_err_prefix(&err, "%s vs %s: ", files[0], files[1]);
        rc = fail(&err);
    } else if (heatmap && !write_heatmap(heatmap, &a, &b, scale, &err)) {
        rc = fail(&err);
    } else if (json) {
        print_json(&m, a.width, a.height);
    } else {
        print_text(&m, a.width, a.height, files[0], files[1]);
    }
    if (rc == ST_EXIT_OK) st_warn_reference_noise("compare", files[1], &m, meta.spp);
    if (rc == ST_EXIT_OK) st_warn_filter_mismatch("compare", files[0], &meta_a, files[1], &meta);
    st_image_free(&a);
    st_image_free(&b);
    st_image_free(&bs);
    if (rc == ST_EXIT_OK && fflush(stdout) != 0) {
        fprintf(stderr, "strahl compare: cannot write output\n");
        rc = ST_EXIT_RUNTIME;
    }
    return rc;
}
