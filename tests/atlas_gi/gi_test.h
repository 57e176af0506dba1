// Helpers shared by the atlas_gi and ssgi tests: scenes written to the
// scratch folder, rendered by the `strahl` command to EXR, and a head-on
// camera that maps a unit square receiver onto exactly K x K pixels, so the
// mean of those pixels is the midpoint rule for the receiver's area average.
#ifndef GI_TEST_H
#define GI_TEST_H
#include "st_test_render.h"

#define GI_PI 3.14159265358979323846

// Writes `json` to SCRATCH/name.json, renders SCRATCH/name.exr with `extra`
// arguments and reads it; 0 on any failure (already reported).
static inline int gi_render(const char *name, const char *json, const char *extra, st_image *img) {
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/%s.json", ST_TEST_SCRATCH, name);
    snprintf(out, sizeof out, "%s/%s.exr", ST_TEST_SCRATCH, name);
    st_test_write(scene, json);
    int rc = st_test_render(scene, out, extra);
    CHECK(rc == 0, "%s: render exit code %d", name, rc);
    if (rc != 0) return 0;
    int read = st_test_read(out, img);
    CHECK(read, "%s: %s is readable", name, out);
    if (!read) return 0;
    CHECK(st_test_all_finite(img), "%s: all pixels finite", name);
    return 1;
}

// The camera for a receiver [0,1] x {0} x [0,1] facing +y seen from height D
// straight down: the square covers exactly the central K x K pixels of an
// H x H image.
// A negative D looks up from below.
static inline double gi_headon_fov(int H, int K, double D) {
    return 2.0 * atan(H / (2.0 * fabs(D) * K)) * 180.0 / GI_PI;
}
static inline void gi_headon_camera(char *out, size_t n, int H, int K, double D) {
    snprintf(out, n,
             "\"camera\": {\"position\": [0.5, %.17g, 0.5], \"target\": [0.5, 0, 0.5], \"up\": [0, "
             "0, -1], "
             "\"fov_y\": %.17g, \"near\": 0.01, \"far\": 100}",
             D, gi_headon_fov(H, K, D));
}

// Mean of channel c over the central K x K pixels.
static inline double gi_headon_mean(const st_image *img, int K, int c) {
    int o = (img->width - K) / 2;
    double s = 0;
    for (int j = o; j < o + K; j++)
        for (int i = o; i < o + K; i++)
            s += st_image_px(img, i, j)[c];
    return s / ((double)K * K);
}

// Mean of channel 0 over the pixels where `mask` is lit (count: how many;
// may be NULL).
static inline double gi_masked_mean(const st_image *img, const st_image *mask, int *count) {
    double s = 0;
    int n = 0;
    for (int j = 0; j < img->height; j++)
        for (int i = 0; i < img->width; i++)
            if (st_image_px(mask, i, j)[0] > 0) s += st_image_px(img, i, j)[0], n++;
    if (count) *count = n;
    return n ? s / n : 0;
}

// Mean of cos(theta_x) between a uniform point x of the receiver (normal +y,
// y = 0) and a uniform point of a parallelogram sender (corner c, edges u, v)
// that faces it: the thesis estimator's expectation per unit atlas fraction.
// Midpoint rule, n^4 points.
static inline double gi_mean_cos_receiver(const double c[3], const double u[3], const double v[3],
                                          int n) {
    double s = 0;
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++) {
            double x[3] = {(a + 0.5) / n, 0, (b + 0.5) / n};
            for (int e = 0; e < n; e++)
                for (int f = 0; f < n; f++) {
                    double p[3], d2 = 0;
                    for (int k = 0; k < 3; k++) {
                        p[k] = c[k] + (e + 0.5) / n * u[k] + (f + 0.5) / n * v[k] - x[k];
                        d2 += p[k] * p[k];
                    }
                    double cx = p[1] / sqrt(d2);
                    s += cx > 0 ? cx : 0;
                }
        }
    return s / ((double)n * n * n * n);
}
#endif
