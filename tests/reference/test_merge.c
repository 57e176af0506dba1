// `strahl reference --seed` shards merged by `strahl merge`.
//
// Four shards (4, 4, 8, 16 spp, seeds 1..4) of a scene with a medium are
// merged and compared with one run of the summed 32 spp (seed 99). Both are
// unbiased estimates of the same image with independent noise, so per value
// d = merged - single has variance s_m^2 + s_r^2 (their reported standard
// errors), and chi2 = sum d^2 / (s_m^2 + s_r^2) over the K values with noise
// is about K: with ~30 degrees of freedom in each variance estimate, d^2 /
// (s_m^2 + s_r^2) is near a squared t variable (mean 1.07, variance 2.3), so
// chi2 / K = 1.07 +- sqrt(2.3 / K), +- 0.03 for the K ~ 2100 values of this
// 64x64 image that see the medium's noise; we accept [0.8, 1.35], about 9 of
// those, since the march's samples are not Gaussian. The merged mean and
// standard error are also checked value by value against the formulas, and
// the merged noise level against the single run's: the same spp, but the
// Sobol sampler (the default) stratifies each of the 16 batches of a pixel
// over its own samples, 2 in the single run of 32 and 1 in the shards of 4,
// so the single run is less noisy (measured 1.40x); merged shards stay
// within sqrt(2) of it (accepted [0.85, 1.45]).
#include "st_test.h"
#include "st_base.h"
#include "st_image.h"

static char dir[4096];

static int sh(const char *args) {
    return st_test_sh("cd '%s' && '%s' %s", dir, ST_TEST_STRAHL, args);
}

static void load(const char *name, st_image *rgb, st_image *se, st_exr_meta *meta) {
    static const char *const names[] = {"R", "G", "B"};
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    st_err e = {0};
    CHECK(st_image_read_exr_channels(path, names, 3, rgb, &e), "%s", e.msg);
    CHECK(st_image_read_exr_stderr(path, se, &e) && se->data, "%s: %s", name, e.msg);
    CHECK(st_image_read_exr_meta(path, meta, &e), "%s", e.msg);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    char cmd[8192];
    const int spp[4] = {4, 4, 8, 16};
    // The point filter: only the march's jitter is random.
    const char *common = "--size 64x64 --bounces 0 --steps 64 --threads 2 --filter point";
    for (int k = 0; k < 4; k++) {
        snprintf(cmd, sizeof cmd,
                 "reference '%s/scenes/godrays_window.json' -o s%d.exr %s --spp %d --seed %d",
                 ST_TEST_SOURCE_DIR, k + 1, common, spp[k], k + 1);
        CHECK(sh(cmd) == 0, "shard %d", k + 1);
    }
    snprintf(cmd, sizeof cmd,
             "reference '%s/scenes/godrays_window.json' -o one.exr %s --spp 32 --seed 99",
             ST_TEST_SOURCE_DIR, common);
    CHECK(sh(cmd) == 0, "single run");
    CHECK(sh("merge s1.exr s2.exr s3.exr s4.exr -o merged.exr") == 0, "merge");

    st_image m = {0}, ms = {0}, r = {0}, rs = {0}, s[4] = {{0}}, ss[4] = {{0}};
    st_exr_meta mm, rm, sm[4];
    load("merged.exr", &m, &ms, &mm);
    load("one.exr", &r, &rs, &rm);
    for (int k = 0; k < 4; k++) {
        char name[32];
        snprintf(name, sizeof name, "s%d.exr", k + 1);
        load(name, &s[k], &ss[k], &sm[k]);
        CHECK(sm[k].spp == spp[k], "shard %d header spp %d", k + 1, sm[k].spp);
    }
    CHECK(mm.spp == 32, "merged spp %d", mm.spp);
    CHECK(!strcmp(mm.seeds, "1,2,3,4"), "merged seeds '%s'", mm.seeds);
    CHECK(!strcmp(mm.config, rm.config) && mm.config[0], "config '%s' vs '%s'", mm.config,
          rm.config);

    const size_t n = (size_t)m.width * m.height * 3;
    double chi2 = 0, vm = 0, vr = 0, worst_mean = 0, worst_se = 0;
    int k_noisy = 0, exact_bad = 0;
    for (size_t i = 0; i < n; i++) {
        double mean = 0, var = 0;
        for (int k = 0; k < 4; k++) {
            mean += spp[k] * (double)s[k].data[i];
            var += (double)spp[k] * spp[k] * ss[k].data[i] * ss[k].data[i];
        }
        mean /= 32;
        double se = sqrt(var) / 32;
        worst_mean = fmax(worst_mean, fabs(m.data[i] - mean) / (fabs(mean) + 1e-6));
        worst_se = fmax(worst_se, fabs(ms.data[i] - se) / (se + 1e-9));
        double v = (double)ms.data[i] * ms.data[i] + (double)rs.data[i] * rs.data[i];
        double d = (double)m.data[i] - r.data[i];
        if (v > 0) {
            chi2 += d * d / v;
            k_noisy++;
            vm += (double)ms.data[i] * ms.data[i];
            vr += (double)rs.data[i] * rs.data[i];
        } else if (fabs(d) > 1e-6 * fabs(r.data[i]) + 1e-9) {
            exact_bad++; // noise-free values (no medium sample) must agree
        }
    }
    fprintf(
        stderr,
        "chi2/K = %.4f (K = %d), noise ratio merged/single %.4f, worst mean %.3g, worst se %.3g\n",
        chi2 / k_noisy, k_noisy, sqrt(vm / vr), worst_mean, worst_se);
    CHECK(k_noisy > 1500, "only %d values with noise", k_noisy);
    CHECK(chi2 / k_noisy > 0.8 && chi2 / k_noisy < 1.35, "chi2/K = %.4f", chi2 / k_noisy);
    CHECK(sqrt(vm / vr) > 0.85 && sqrt(vm / vr) < 1.45, "merged noise / single-run noise = %.4f",
          sqrt(vm / vr));
    CHECK(worst_mean < 1e-5, "merged mean differs from sum n_i m_i / N by %.3g", worst_mean);
    CHECK(worst_se < 1e-5, "merged stderr differs from sqrt(sum n_i^2 s_i^2) / N by %.3g",
          worst_se);
    CHECK(exact_bad == 0, "%d noise-free values differ", exact_bad);

    // Merging a merged file with a further shard: 32 + 8 spp, seeds appended.
    CHECK(sh("reference '" ST_TEST_SOURCE_DIR
             "/scenes/godrays_window.json' -o s5.exr --size 64x64 --bounces 0 "
             "--steps 64 --threads 2 --spp 8 --seed 5 --filter point") == 0,
          "shard 5");
    CHECK(sh("merge merged.exr s5.exr -o merged2.exr") == 0, "merge again");
    st_image m2 = {0}, m2s = {0};
    st_exr_meta m2m;
    load("merged2.exr", &m2, &m2s, &m2m);
    CHECK(m2m.spp == 40 && !strcmp(m2m.seeds, "1,2,3,4,5"), "spp %d seeds '%s'", m2m.spp,
          m2m.seeds);

    // Bad input: exit 2 and no output file.
    unlink("bad.exr");
    CHECK(sh("merge s1.exr s1.exr -o bad.exr") == 2, "a seed twice");
    CHECK(sh("merge merged.exr s2.exr -o bad.exr") == 2, "a seed inside a merged file");
    // A shard with the other pixel filter is another render (strahl.config).
    CHECK(sh("reference '" ST_TEST_SOURCE_DIR
             "/scenes/godrays_window.json' -o box.exr --size 64x64 --bounces 0 "
             "--steps 64 --threads 2 --spp 4 --seed 9 --filter box") == 0,
          "box shard");
    CHECK(sh("merge merged.exr box.exr -o bad.exr") == 2, "point and box shards merged");
    CHECK(sh("reference '" ST_TEST_SOURCE_DIR
             "/scenes/godrays_window.json' -o other.exr --size 64x64 --bounces 0 "
             "--steps 32 --threads 2 --spp 4 --seed 7") == 0,
          "other config");
    CHECK(sh("merge s1.exr other.exr -o bad.exr") == 2, "different --steps");
    CHECK(sh("reference '" ST_TEST_SOURCE_DIR
             "/scenes/godrays_window.json' -o small.exr --size 32x64 --bounces 0 "
             "--steps 64 --threads 2 --spp 4 --seed 8") == 0,
          "other size");
    CHECK(sh("merge s1.exr small.exr -o bad.exr") == 2, "different size");
    st_image plain = {0};
    st_err e = {0};
    st_image_alloc(&plain, 64, 64, 3, &e);
    char path[4200];
    snprintf(path, sizeof path, "%s/plain.exr", dir);
    st_image_write_exr(path, &plain, &e);
    CHECK(sh("merge s1.exr plain.exr -o bad.exr") == 2, "no stderr channels");
    CHECK(sh("merge s1.exr -o bad.png") == 2, "png output");
    snprintf(path, sizeof path, "%s/bad.exr", dir);
    CHECK(!st_test_exists(path), "bad.exr written");
    st_image *all[] = {&m, &ms, &r, &rs, &m2, &m2s, &plain};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        st_image_free(all[i]);
    for (int k = 0; k < 4; k++)
        st_image_free(&s[k]), st_image_free(&ss[k]);
    return st_test_summary("reference_merge");
}
