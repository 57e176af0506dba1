// The reference's box filter (st_ref_options.filter): a 12 x 12 image of a lit
// floor under a floating quad (its black back side and its shadow give sharp
// edges) in a thin medium, box-filtered with 256 samples per pixel, matches
// the 16 x 16 supersampled point-filtered reference (2 samples per point, so
// that its standard error is known too) averaged down, within
// the two images' standard errors; the point-filtered 12 x 12 image does not.
// The box image uses independent numbers over the stratified grid, whose
// noise this test's bounds were set for; the Sobol sampler (the default) is
// held against it in test_zscore.c.
#include "ref_test_util.h"

#define N 12
#define SS 16

static void build(st_scene *s, int size) {
    const double pos[3] = {0.4, 2.2, 2.6}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    scene_init(s, size, size, pos, target, up, 50, 50);
    const double fc[3] = {-2, 0, 2}, fu[3] = {4, 0, 0}, fv[3] = {0, 0, -4};
    add_quad(s, fc, fu, fv, 0.7, 0); // floor, facing +y
    const double oc[3] = {-0.35, 0.6, -0.3}, ou[3] = {0, 0, 0.7}, ov[3] = {0.6, 0, 0.1};
    add_quad(s, oc, ou, ov, 0.5, 0); // occluder, facing -y
    st_light_desc l;
    memset(&l, 0, sizeof l);
    v3(l.position, 0.2, 1.8, 0.1);
    v3(l.intensity, 4, 4, 4);
    st_err err = {0};
    if (!st_scene_add_light(s, &l, &err)) exit(1);
    set_medium(s, 0.08, 0.02, ST_PHASE_ISOTROPIC, 0);
}

int main(void) {
    st_scene s, big;
    build(&s, N);
    build(&big, N * SS);
    st_image box = {0}, point = {0}, ss = {0};
    st_ref_options ob = {.spp = 256,
                         .march_steps = 16,
                         .seed = 3,
                         .filter = ST_FILTER_BOX,
                         .sampler = ST_REF_SAMPLER_INDEPENDENT};
    st_ref_options op = {.spp = 64, .march_steps = 16, .seed = 4};
    st_ref_options os = {.spp = 2, .march_steps = 16, .seed = 5};
    CHECK(render(&s, &ob, &box) && render(&s, &op, &point) && render(&big, &os, &ss), "renders");
    if (!box.data || !point.data || !ss.data) return st_test_summary("reference_filter");
    double d2_box = 0, d2_point = 0, var = 0, max_z = 0, mean_box = 0, mean_ss = 0;
    int far = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                // The supersampled pixel: mean of its SS x SS centres, and its
                // standard error from theirs.
                double m = 0, se2 = 0;
                for (int b = 0; b < SS; b++)
                    for (int a = 0; a < SS; a++) {
                        const float *p = st_image_px(&ss, i * SS + a, j * SS + b);
                        m += p[c], se2 += (double)p[3 + c] * p[3 + c];
                    }
                m /= SS * SS, se2 /= (double)SS * SS * SS * SS;
                const float *pb = st_image_px(&box, i, j), *pp = st_image_px(&point, i, j);
                double sigma2 = (double)pb[3 + c] * pb[3 + c] + se2;
                double d = pb[c] - m;
                d2_box += d * d, d2_point += (pp[c] - m) * (pp[c] - m), var += sigma2;
                double z = fabs(d) / sqrt(sigma2 + 1e-12);
                max_z = fmax(max_z, z);
                far += z > 4;
                mean_box += pb[c], mean_ss += m;
            }
    int n = N * N * 3;
    printf("box vs supersampled: rms %.5f (expected from the standard errors %.5f), max |z| "
           "%.2f, %d beyond 4 sigma; point vs supersampled: rms %.5f; means %.5f, %.5f\n",
           sqrt(d2_box / n), sqrt(var / n), max_z, far, sqrt(d2_point / n), mean_box / n,
           mean_ss / n);
    // Within the noise: the mean squared difference is what the standard
    // errors allow (they overstate stratified samples' noise, so <= 1.5x),
    // no pixel far out, and the image means agree.
    CHECK(d2_box <= 1.5 * var, "box vs supersampled: rms %g, standard errors allow %g",
          sqrt(d2_box / n), sqrt(var / n));
    CHECK(far <= n / 100, "%d of %d values beyond 4 sigma", far, n);
    CHECK(fabs(mean_box - mean_ss) / n <= 3 * sqrt(var) / n, "means %g vs %g", mean_box / n,
          mean_ss / n);
    // The point filter misses the edges by far more.
    CHECK(d2_point >= 10 * d2_box, "point rms %g is not well above box rms %g", sqrt(d2_point / n),
          sqrt(d2_box / n));
    // Standard errors exist where the pixel's square is not uniform.
    double se_max = 0;
    for (size_t k = 0; k < (size_t)N * N; k++)
        se_max = fmax(se_max, box.data[6 * k + 3]);
    CHECK(se_max > 0, "box filter: no standard error anywhere");
    st_image_free(&box);
    st_image_free(&point);
    st_image_free(&ss);
    st_scene_free(&s);
    st_scene_free(&big);
    return st_test_summary("reference_filter");
}
