// Honest standard errors with the Sobol sampler (`strahl reference`, its
// default): two runs with independent seeds are independent estimates of
// one image, so per value z = (a - b) / sqrt(s_a^2 + s_b^2) has mean 0 and,
// if the stderr channels are honest, variance 1 up to the estimates' own
// noise: each s^2 comes from 16 batch means (15 degrees of freedom), so z
// is near Student-t with ~30, E[z^2] = 30/28 = 1.07. Over the 700-2300
// independent pixels with noise (channels are correlated) E[z^2] has a
// standard deviation of 0.03-0.06: accepted [0.9, 1.3]. A Welford stderr that
// treated the correlated samples of a batch as independent would give
// ~0.5 (the sampler's variance gain), one that ignored the batches' spread ~2.
// Cases: a Cornell box with a bounce over the pixel's box, and a god-ray
// window at pixel centres (in-scattering). A Sobol run and an independent
// one agree the same way (both unbiased), and at equal spp the Sobol run is
// less noisy (the point of the sampler). Also --target-error.
#include "st_test.h"
#include "st_base.h"
#include "st_image.h"

static char dir[4096];

static bool load(const char *name, st_image *rgb, st_image *se) {
    static const char *const names[] = {"R", "G", "B"};
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    st_err e = {0};
    bool ok = st_image_read_exr_channels(path, names, 3, rgb, &e) &&
              st_image_read_exr_stderr(path, se, &e) && se->data;
    CHECK(ok, "%s: %s", name, e.msg);
    return ok;
}

static void run(const char *scene, const char *opts, const char *out, int seed) {
    CHECK(st_test_sh("cd '%s' && '%s' reference '%s/%s' -o %s %s --threads 2 --seed %d", dir,
                     ST_TEST_STRAHL, ST_TEST_SOURCE_DIR, scene, out, opts, seed) == 0,
          "%s %s", scene, opts);
}

// Mean z^2 of two runs with seeds 1 and 2 (options a and b).
static void one_case(const char *label, const char *scene, const char *a_opts, const char *b_opts) {
    run(scene, a_opts, "z1.exr", 1);
    run(scene, b_opts, "z2.exr", 2);
    st_image a = {0}, sa = {0}, b = {0}, sb = {0};
    if (!load("z1.exr", &a, &sa) || !load("z2.exr", &b, &sb)) return;
    double z2 = 0, se2 = 0;
    int k = 0;
    for (size_t i = 0; i < (size_t)a.width * a.height * 3; i++) {
        double v = (double)sa.data[i] * sa.data[i] + (double)sb.data[i] * sb.data[i];
        if (!(v > 0)) continue;
        double d = (double)a.data[i] - b.data[i];
        z2 += d * d / v, se2 += (double)sa.data[i] * sa.data[i], k++;
    }
    printf("  %s: E[z^2] = %.4f over %d values, rms stderr %.4g\n", label, z2 / k, k,
           sqrt(se2 / k));
    CHECK(k > 1500, "%s: only %d values with noise", label, k);
    CHECK(z2 / k > 0.9 && z2 / k < 1.3, "%s: E[z^2] = %.4f", label, z2 / k);
    st_image *all[] = {&a, &sa, &b, &sb};
    for (int i = 0; i < 4; i++)
        st_image_free(all[i]);
}

// The rms standard error of one run.
static double rms_se(const char *scene, const char *opts) {
    run(scene, opts, "g.exr", 3);
    st_image a = {0}, sa = {0};
    if (!load("g.exr", &a, &sa)) return NAN;
    double se2 = 0;
    size_t n = (size_t)a.width * a.height * 3;
    for (size_t i = 0; i < n; i++)
        se2 += (double)sa.data[i] * sa.data[i];
    st_image_free(&a), st_image_free(&sa);
    return sqrt(se2 / n);
}

// --target-error: passes until sqrt(mean stderr^2) / mean <= E; the header's
// spp is the total, and the file's own stderr channels show the error.
static void target_error(const char *scene) {
    const char *opts = "--size 24x24 --spp 16 --bounces 1 --filter point";
    double first = rms_se(scene, opts);
    char topts[256];
    snprintf(topts, sizeof topts, "%s --target-error 0.02", opts);
    run(scene, topts, "t.exr", 3);
    st_image a = {0}, sa = {0};
    st_exr_meta meta;
    char path[4200];
    snprintf(path, sizeof path, "%s/t.exr", dir);
    st_err e = {0};
    if (!load("t.exr", &a, &sa) || !st_image_read_exr_meta(path, &meta, &e)) return;
    double se2 = 0, sum = 0;
    size_t n = (size_t)a.width * a.height * 3;
    for (size_t i = 0; i < n; i++)
        se2 += (double)sa.data[i] * sa.data[i], sum += fabs(a.data[i]);
    double rel = sqrt(se2 / n) / (sum / n);
    printf("  --target-error 0.02: %d spp, relative error %.4f (16 spp: rms stderr %.4g)\n",
           meta.spp, rel, first);
    CHECK(rel <= 0.02 && rel > 0.01, "relative error reached %.4f", rel);
    CHECK(meta.spp > 16, "header spp %d", meta.spp);
    CHECK(st_test_sh("'%s' reference '%s/%s' -o %s/bad.exr --target-error 0", ST_TEST_STRAHL,
                     ST_TEST_SOURCE_DIR, scene, dir) == 2,
          "--target-error 0 is refused");
    st_image_free(&a), st_image_free(&sa);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    const char *cornell = "tests/data/crosscheck/cornell_front.json";
    const char *copts = "--size 48x48 --spp 64 --bounces 1 --filter box";
    char iopts[256];
    snprintf(iopts, sizeof iopts, "%s --sampler independent", copts);
    const char *gopts = "--size 64x64 --spp 32 --bounces 0 --steps 16 --filter point";
    one_case("cornell box filter", cornell, copts, copts);
    one_case("god-ray window", "scenes/godrays_window.json", gopts, gopts);
    // The same expectation as independent numbers (an unbiased sampler).
    one_case("cornell, sobol vs independent", cornell, copts, iopts);
    // The gain: pixel centres (the bounce alone), 16 samples per batch.
    const char *popts = "--size 32x32 --spp 256 --bounces 1 --filter point";
    snprintf(iopts, sizeof iopts, "%s --sampler independent", popts);
    double sobol = rms_se(cornell, popts), indep = rms_se(cornell, iopts);
    printf("  cornell 256 spp: rms stderr sobol %.4g, independent %.4g (%.2fx)\n", sobol, indep,
           indep / sobol);
    CHECK(indep > 1.25 * sobol, "sobol %.4g not below independent %.4g / 1.25", sobol, indep);
    target_error(cornell);
    return st_test_summary("reference_zscore");
}
