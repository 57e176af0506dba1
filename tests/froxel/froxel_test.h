// Shared helpers of the froxel tests: render a scene with froxel, render the
// CPU reference (single scattering with exact visibility, no bounces) of the
// same scene on the same pixel filter, and their NRMSE (rmse over R, G, B
// with the reference's own noise removed, over the reference's mean).
#ifndef FROXEL_TEST_H
#define FROXEL_TEST_H
#include "st_test_render.h" // first: it defines _GNU_SOURCE

typedef struct {
    double nrmse; // debiased rmse / mean of the reference
    double noise; // the reference's rms standard error / its mean
    double mean_a, mean_b;
    int ok;
} froxel_cmp;

// Renders `scene` with froxel (extra: more options, e.g. --set froxel.x=y)
// and `ref` as `strahl reference` output (made once per scene by the caller)
// and compares them on the point filter.
static inline froxel_cmp froxel_compare(const char *scene, const char *ref, const char *out,
                                        const char *extra) {
    froxel_cmp r = {INFINITY, INFINITY, 0, 0, 0};
    int rc = st_test_render(scene, out, extra);
    CHECK(rc == 0, "render %s %s: exit %d", scene, extra ? extra : "", rc);
    st_image a = {0}, b = {0}, bs = {0};
    st_err err = {0};
    st_metrics m;
    if (rc != 0 || !st_test_read(out, &a) || !st_test_read(ref, &b)) return r;
    CHECK(st_test_all_finite(&a), "%s: every pixel finite", out);
    if (!st_image_read_exr_stderr(ref, &bs, &err) ||
        !st_image_compare_noisy(&a, &b, &bs, &m, &err)) {
        CHECK(false, "compare %s: %s", ref, err.msg);
    } else {
        r.nrmse = m.mean_b[3] > 0 ? m.rmse_debiased[3] / m.mean_b[3] : INFINITY;
        r.noise = m.mean_b[3] > 0 ? m.ref_noise_rms[3] / m.mean_b[3] : INFINITY;
        r.mean_a = m.mean_a[3];
        r.mean_b = m.mean_b[3];
        r.ok = 1;
    }
    st_image_free(&a);
    st_image_free(&b);
    st_image_free(&bs);
    return r;
}

// The reference of `scene` (extra: e.g. --size), point filter, no bounces.
static inline int froxel_reference(const char *scene, const char *ref, int spp, const char *extra) {
    unlink(ref);
    int rc = st_test_sh("%s reference %s -o %s --spp %d --bounces 0 --filter point %s >/dev/null",
                        ST_TEST_STRAHL, scene, ref, spp, extra ? extra : "");
    CHECK(rc == 0, "reference %s: exit %d", scene, rc);
    return rc == 0;
}
#endif
