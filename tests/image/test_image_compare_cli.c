// `strahl compare`: JSON values, text output, exit codes and messages for bad
// input, heat map written only on success.
#include "st_test.h"
#include "st_base.h"
#include "st_image.h"

static char dir[4096];

static void path_of(char *out, size_t n, const char *name) {
    snprintf(out, n, "%s/%s", dir, name);
}

// Writes a 2x2 RGB EXR from per-channel arrays.
static void write_exr(const char *name, int w, int h, const float *r, const float *g,
                      const float *b) {
    char path[4200];
    path_of(path, sizeof path, name);
    st_image img;
    st_err err = {0};
    st_image_alloc(&img, w, h, 3, &err);
    for (int k = 0; k < w * h; k++) {
        img.data[3 * k] = r[k];
        img.data[3 * k + 1] = g[k];
        img.data[3 * k + 2] = b[k];
    }
    CHECK(st_image_write_exr(path, &img, &err), "%s", err.msg);
    st_image_free(&img);
}

// Runs `strahl compare ARGS` with stdout and stderr in files; returns the
// exit code and fills out/err_text.
static int run(const char *args, char **out, char **err_text) {
    char o[4200], e[4200];
    path_of(o, sizeof o, "stdout.txt");
    path_of(e, sizeof e, "stderr.txt");
    int rc = st_test_sh("cd '%s' && '%s' compare %s >'%s' 2>'%s'", dir, ST_TEST_STRAHL, args, o, e);
    st_err err = {0};
    *out = st_read_file(o, NULL, &err);
    *err_text = st_read_file(e, NULL, &err);
    fprintf(stderr, "stdout: %s\nstderr: %s\n", *out ? *out : "", *err_text ? *err_text : "");
    return rc;
}

// Value of "key":{... "sub":VALUE ...} (sub NULL: "key":VALUE); NAN when the
// value is missing or null.
static double json_get(const char *json, const char *key, const char *sub) {
    char k[64];
    snprintf(k, sizeof k, "\"%s\":", key);
    const char *p = json ? strstr(json, k) : NULL;
    if (!p) return NAN;
    p += strlen(k);
    if (sub) {
        const char *end = strchr(p, '}');
        snprintf(k, sizeof k, "\"%s\":", sub);
        p = strstr(p, k);
        if (!p || (end && p > end)) return NAN;
        p += strlen(k);
    }
    if (!strncmp(p, "null", 4)) return NAN;
    char *e;
    double v = strtod(p, &e);
    return e == p ? NAN : v;
}

static int count_lines(const char *s) {
    int n = 0;
    for (; s && *s; s++)
        n += *s == '\n';
    return n;
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    // The worked example of test_image_metrics: b the reference.
    const float bR[4] = {1, 2, 3, 4}, bG[4] = {0, 0, 0, 0}, bB[4] = {2, 2, 2, 2};
    const float aR[4] = {1, 2, 3, 6}, aG[4] = {0, 0.5f, 0, 0};
    write_exr("a.exr", 2, 2, aR, aG, bB);
    write_exr("b.exr", 2, 2, bR, bG, bB);
    const float wide[6] = {1, 1, 1, 1, 1, 1};
    write_exr("wide.exr", 3, 2, wide, wide, wide);
    char *out, *err;

    int rc = run("a.exr b.exr --json", &out, &err);
    CHECK(rc == 0, "exit %d", rc);
    CHECK(out && out[0] == '{' && count_lines(out) == 1, "one JSON line");
    CHECK_REL(json_get(out, "rmse", "r"), 1.0, 1e-8, 0);
    CHECK_REL(json_get(out, "rmse", "g"), 0.25, 1e-8, 0);
    CHECK_REL(json_get(out, "rmse", "all"), 0.5951190357119042, 1e-8, 0);
    CHECK_REL(json_get(out, "relmse", "g"), 6.25, 1e-8, 0);
    CHECK_REL(json_get(out, "psnr", "r"), 12.041199826559248, 1e-8, 0);
    CHECK(out && strstr(out, "\"psnr\":{\"r\":12.0411998,\"g\":24.0823997,\"b\":null,"),
          "psnr of an exact channel is null");
    CHECK_REL(json_get(out, "max_abs", "all"), 2.0, 1e-8, 0);
    CHECK_REL(json_get(out, "scale", NULL), 54.0 / 66.25, 1e-8, 0);
    CHECK_REL(json_get(out, "scaled_rmse", "all"), 0.40670481314025114, 1e-8, 0);
    CHECK_REL(json_get(out, "mean_a", "r"), 3.0, 1e-8, 0);
    CHECK_REL(json_get(out, "mean_b", "all"), 1.5, 1e-8, 0);
    CHECK(json_get(out, "width", NULL) == 2 && json_get(out, "height", NULL) == 2, "size");
    CHECK(err && !err[0], "nothing on stderr");
    free(out);
    free(err);

    // Identical images: every psnr null in JSON, "inf" in text.
    rc = run("--json b.exr b.exr", &out, &err);
    CHECK(rc == 0 && out && strstr(out, "\"psnr\":{\"r\":null,\"g\":null,\"b\":null,\"all\":null}"),
          "identical psnr null");
    CHECK(json_get(out, "rmse", "all") == 0.0, "identical rmse 0");
    free(out);
    free(err);
    rc = run("b.exr b.exr", &out, &err);
    CHECK(rc == 0 && out && strstr(out, "psnr") && strstr(out, "inf"), "text psnr inf");
    free(out);
    free(err);

    // Text output: one line per metric with R, G, B, all.
    rc = run("a.exr b.exr", &out, &err);
    CHECK(rc == 0, "text exit %d", rc);
    const char *line = out ? strstr(out, "\nrmse ") : NULL;
    double r = NAN, g = NAN, b = NAN, all = NAN;
    if (line) sscanf(line, " rmse %lf %lf %lf %lf", &r, &g, &b, &all);
    CHECK(r == 1.0 && g == 0.25 && b == 0.0 && fabs(all - 0.5951190357) < 1e-9,
          "text rmse %g %g %g %g", r, g, b, all);
    CHECK(out && strstr(out, "\nscaled_rmse ") && strstr(out, "\nmax_abs ") &&
              strstr(out, "\nrelmse ") && strstr(out, "\nscale "),
          "all metrics printed");
    free(out);
    free(err);

    // Heat map written on success.
    char heat[4200];
    path_of(heat, sizeof heat, "heat.png");
    unlink(heat);
    rc = run("a.exr b.exr --heatmap heat.png", &out, &err);
    CHECK(rc == 0 && st_test_exists(heat), "heat map written (exit %d)", rc);
    size_t len = 0;
    st_err e2 = {0};
    char *png = st_read_file(heat, &len, &e2);
    // PNG signature, then IHDR: the 2x2 map padded to 96 wide, 24 rows of
    // colour bar below (big endian).
    CHECK(png && len > 24 && !memcmp(png, "\x89PNG\r\n\x1a\n", 8) && png[19] == 96 &&
              png[23] == 2 + 24,
          "heat map is a 2x2 PNG with its legend");
    free(png);
    free(out);
    free(err);

    // Bad input: exit 2, one message line naming the culprit, no heat map.
    path_of(heat, sizeof heat, "heat-fail.png");
    unlink(heat);
    rc = run("a.exr wide.exr --json --heatmap heat-fail.png", &out, &err);
    CHECK(rc == 2, "size mismatch exit %d", rc);
    CHECK(err && strstr(err, "wide.exr") && strstr(err, "3x2") && strstr(err, "2x2") &&
              count_lines(err) == 1,
          "size mismatch message: %s", err);
    CHECK(out && !out[0], "no stdout on failure");
    CHECK(!st_test_exists(heat), "no heat map on failure");
    free(out);
    free(err);

    rc = run("a.exr missing.exr --heatmap heat-fail.png", &out, &err);
    CHECK(rc == 2 && err && strstr(err, "missing.exr") && count_lines(err) == 1,
          "missing file: exit %d, %s", rc, err);
    CHECK(!st_test_exists(heat), "no heat map on missing file");
    free(out);
    free(err);

    char text[4200];
    path_of(text, sizeof text, "text.exr");
    FILE *f = fopen(text, "w");
    fputs("not an EXR\n", f);
    fclose(f);
    rc = run("text.exr b.exr", &out, &err);
    CHECK(rc == 2 && err && strstr(err, "text.exr"), "not an EXR: exit %d, %s", rc, err);
    free(out);
    free(err);

    rc = run("a.exr b.exr --bogus", &out, &err);
    CHECK(rc == 2 && err && strstr(err, "--bogus"), "unknown option: exit %d", rc);
    free(out);
    free(err);

    rc = run("a.exr", &out, &err);
    CHECK(rc == 2 && err && count_lines(err) == 1, "one file: exit %d", rc);
    free(out);
    free(err);

    rc = run("a.exr b.exr c.exr", &out, &err);
    CHECK(rc == 2 && err && strstr(err, "c.exr"), "three files: exit %d", rc);
    free(out);
    free(err);

    rc = run("a.exr b.exr --heatmap", &out, &err);
    CHECK(rc == 2, "--heatmap without a file: exit %d", rc);
    free(out);
    free(err);

    // Heat map into a missing directory is bad input, found before any work.
    rc = run("a.exr b.exr --heatmap no/such/dir/h.png", &out, &err);
    CHECK(rc == 2 && err && strstr(err, "no/such/dir/h.png") && out && !out[0],
          "unwritable heat map: exit %d", rc);
    free(out);
    free(err);

    return st_test_summary("test_image_compare_cli");
}
