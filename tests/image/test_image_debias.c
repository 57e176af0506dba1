// Debiased errors against a noisy reference (st_image_compare_noisy) and the
// noise warning of `strahl compare`, on synthetic images with known noise.
//
// Oracle. Pixel values mu, a test image a = mu + delta (delta known), a
// reference b = mu + sigma z (z standard normal) that reports its standard
// error s = sigma. Per value, with d = a - b = delta - sigma z:
//   E[d^2 - s^2] = delta^2,  Var[d^2 - s^2] = 4 delta^2 sigma^2 + 2 sigma^4,
// so D = mean(d^2 - s^2) over M values has mean E = mean(delta^2) and
// standard deviation sqrt(sum(4 delta^2 sigma^2 + 2 sigma^4)) / M; we accept
// |D - E| <= 6 of those (the images are seeded, so the test is deterministic;
// a fresh draw would fail once in 5e8). With s estimated from n samples
// (s^2 = sample variance / n), Var[s^2] = 2 sigma^4 / (n - 1) adds to it.
// relmse: the same with the weight w = 1/(b^2 + 0.01); after the first-order
// correction the remaining bias is at most mean(|w''(mu)| (delta^2 sigma^2/2
// + sigma^4)), w'' = (6 mu^2 - 0.02) w^3 ... bounded here by 8 w^3 mu^2, which is added to
// the tolerance.
#include "st_test.h"
#include "st_base.h"
#include "st_image.h"

static uint64_t rng_state = 0x853c49e6748fea9bull;
static double uniform(void) { // splitmix64 -> (0, 1)
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return ((z >> 11) + 0.5) / 9007199254740992.0;
}
static double gauss(void) {
    return sqrt(-2 * log(uniform())) * cos(2 * 3.14159265358979323846 * uniform());
}

typedef struct {
    st_image mu, a, b, s;
    double mse, rel, sd_mse, sd_rel, bias_rel;
} synth;

// W x H pixels, mu in [0.5, 2], error delta = err_scale * pattern (sign
// varies), noise sigma = noise_scale * (0.5 .. 1.5); n samples per pixel for
// the reference (n = 0: exact sigma reported).
static void make(synth *y, int w, int h, double err_scale, double noise_scale, int n) {
    st_err e = {0};
    st_image_alloc(&y->mu, w, h, 3, &e);
    st_image_alloc(&y->a, w, h, 3, &e);
    st_image_alloc(&y->b, w, h, 3, &e);
    st_image_alloc(&y->s, w, h, 3, &e);
    double se = 0, sr = 0, vm = 0, vr = 0, br = 0;
    const size_t m = (size_t)w * h * 3;
    for (size_t k = 0; k < m; k++) {
        double mu = 0.5 + 1.5 * uniform();
        double delta = err_scale * (uniform() < 0.3 ? -1.0 : 1.0) * (0.5 + uniform());
        double sigma = noise_scale * (0.5 + uniform());
        double bval, s2;
        if (n == 0) {
            bval = mu + sigma * gauss();
            s2 = sigma * sigma;
        } else { // mean and squared standard error of n samples of sd sigma*sqrt(n)
            double sum = 0, sum2 = 0, sd = sigma * sqrt((double)n);
            for (int i = 0; i < n; i++) {
                double x = mu + sd * gauss();
                sum += x;
                sum2 += x * x;
            }
            bval = sum / n;
            s2 = (sum2 - sum * sum / n) / (n - 1) / n;
        }
        y->mu.data[k] = (float)mu;
        y->a.data[k] = (float)(mu + delta);
        y->b.data[k] = (float)bval;
        y->s.data[k] = (float)sqrt(s2);
        // Oracle sums in the float values the images hold.
        double fd = (double)y->a.data[k] - mu, v = sigma * sigma, wgt = 1 / (mu * mu + 1e-2);
        double var1 = 4 * fd * fd * v + 2 * v * v + (n ? 2 * v * v / (n - 1) : 0);
        se += fd * fd;
        sr += fd * fd * wgt;
        vm += var1;
        vr += var1 * wgt * wgt;
        br += 8 * mu * mu * wgt * wgt * wgt * (fd * fd * v / 2 + v * v);
    }
    y->mse = se / m;
    y->rel = sr / m;
    y->sd_mse = sqrt(vm) / m;
    y->sd_rel = sqrt(vr) / m;
    y->bias_rel = br / m;
}

static void drop(synth *y) {
    st_image_free(&y->mu);
    st_image_free(&y->a);
    st_image_free(&y->b);
    st_image_free(&y->s);
}

static void check_case(const char *name, double err_scale, double noise_scale, int n) {
    synth y = {0};
    make(&y, 128, 128, err_scale, noise_scale, n);
    st_metrics m;
    st_err e = {0};
    CHECK(st_image_compare_noisy(&y.a, &y.b, &y.s, &m, &e), "%s", e.msg);
    double mse = m.rmse_debiased[3] * m.rmse_debiased[3], raw = m.rmse[3] * m.rmse[3];
    fprintf(stderr,
            "%s: true mse %.6g, debiased %.6g (6 sd %.3g), raw %.6g; relmse true %.6g debiased "
            "%.6g raw %.6g\n",
            name, y.mse, mse, 6 * y.sd_mse, raw, y.rel, m.relmse_debiased[3], m.relmse[3]);
    CHECK(fabs(mse - y.mse) <= 6 * y.sd_mse, "%s: debiased mse %.6g, true %.6g, bound %.3g", name,
          mse, y.mse, 6 * y.sd_mse);
    CHECK(fabs(m.relmse_debiased[3] - y.rel) <= 6 * y.sd_rel + y.bias_rel,
          "%s: debiased relmse %.6g, true %.6g, bound %.3g", name, m.relmse_debiased[3], y.rel,
          6 * y.sd_rel + y.bias_rel);
    CHECK(m.has_ref_noise, "%s", name);
    // The reference's noise as reported: rms of s, and raw = true + noise^2.
    double noise2 = m.ref_noise_rms[3] * m.ref_noise_rms[3];
    CHECK(fabs(raw - (y.mse + noise2)) <= 6 * y.sd_mse, "%s: raw mse %.6g, expected %.6g", name,
          raw, y.mse + noise2);
    drop(&y);
}

static int run_compare(const char *dir, const char *a, const char *b, char *out, size_t n) {
    char cmd[8000];
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' compare %s %s --json", dir, ST_TEST_STRAHL, a, b);
    return st_test_capture(out, n, cmd);
}

int main(void) {
    // Noise 3x the error: the raw rmse is off by a factor ~3, the debiased
    // one within its bound.
    check_case("noisy reference", 0.01, 0.03, 0);
    check_case("clean reference", 0.03, 0.003, 0);
    check_case("estimated s, 16 samples", 0.01, 0.03, 16);
    {
        synth y = {0};
        make(&y, 128, 128, 0.01, 0.03, 0);
        st_metrics m;
        st_err e = {0};
        st_image_compare_noisy(&y.a, &y.b, &y.s, &m, &e);
        CHECK(m.rmse[3] > 2.5 * sqrt(y.mse),
              "raw rmse %.4g is not inflated by the noise (true %.4g)", m.rmse[3], sqrt(y.mse));
        CHECK(st_metrics_noise_dominates(&m), "noise 3x the error must warn");
        // Without standard errors: raw numbers, no warning.
        st_metrics p;
        CHECK(st_image_compare_noisy(&y.a, &y.b, NULL, &p, &e), "%s", e.msg);
        CHECK(!p.has_ref_noise && p.rmse_debiased[3] == p.rmse[3] &&
                  !st_metrics_noise_dominates(&p),
              "no stderr");
        // A standard-error image of the wrong size is bad input.
        st_image small = {0};
        st_image_alloc(&small, 4, 4, 3, &e);
        CHECK(!st_image_compare_noisy(&y.a, &y.b, &small, &p, &e) && e.kind == ST_ERR_INPUT,
              "size mismatch");
        st_image_free(&small);

        // strahl compare: the same numbers, and the warning on stderr only
        // when the noise is more than a third of the error.
        char dir[4200], path[4300];
        snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
        static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
        st_image ref6 = {0};
        st_image_alloc(&ref6, 128, 128, 6, &e);
        for (size_t k = 0; k < (size_t)128 * 128; k++)
            for (int c = 0; c < 3; c++) {
                ref6.data[6 * k + c] = y.b.data[3 * k + c];
                ref6.data[6 * k + 3 + c] = y.s.data[3 * k + c];
            }
        st_exr_meta meta = {.spp = 16};
        snprintf(path, sizeof path, "%s/noisy_ref.exr", dir);
        CHECK(st_image_write_exr_meta(path, &ref6, names, &meta, &e), "%s", e.msg);
        snprintf(path, sizeof path, "%s/a.exr", dir);
        CHECK(st_image_write_exr(path, &y.a, &e), "%s", e.msg);
        // 10x less noise: a third of the error is 0.0033 > 0.003 * ~1.04.
        for (size_t k = 0; k < (size_t)128 * 128; k++)
            for (int c = 0; c < 3; c++) {
                float mu = y.mu.data[3 * k + c], bn = y.b.data[3 * k + c];
                ref6.data[6 * k + c] = mu + (bn - mu) / 10;
                ref6.data[6 * k + 3 + c] = y.s.data[3 * k + c] / 10;
            }
        meta.spp = 1600;
        snprintf(path, sizeof path, "%s/clean_ref.exr", dir);
        CHECK(st_image_write_exr_meta(path, &ref6, names, &meta, &e), "%s", e.msg);
        st_image_free(&ref6);

        st_exr_meta back = {0};
        CHECK(st_image_read_exr_meta(path, &back, &e) && back.spp == 1600,
              "spp attribute read back: %d", back.spp);

        char out[16384];
        CHECK(run_compare(dir, "a.exr", "noisy_ref.exr", out, sizeof out) == 0, "compare noisy");
        CHECK(strstr(out, "warning") && strstr(out, "more than a third"),
              "no warning for a noisy reference");
        // spp that brings the noise to a third: 16 (3 noise / err)^2 ~ 16 * 81 = 1296.
        const char *at = strstr(out, "at least ");
        double want = at ? strtod(at + 9, NULL) : 0;
        CHECK(want > 900 && want < 1800, "suggested spp %g, expected ~1300", want);
        CHECK(strstr(out, "\"reference_noise_warning\":true"), "json flag");
        const char *q = strstr(out, "\"rmse_debiased\":");
        CHECK(q != NULL, "json has rmse_debiased");
        CHECK(run_compare(dir, "a.exr", "clean_ref.exr", out, sizeof out) == 0, "compare clean");
        CHECK(!strstr(out, "compare: warning"), "warning for a clean reference");
        CHECK(strstr(out, "\"reference_noise_warning\":false"), "json flag false");
        drop(&y);
    }
    return st_test_summary("image_debias");
}
