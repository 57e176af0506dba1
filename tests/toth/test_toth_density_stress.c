// Stress for the GPU density (common/medium.glsl) with toth marching it:
// extreme height fog (falloff 1e4 /m, bases at +-1e6 m), a grid of zeros,
// a grid of values near float's maximum, a dense scattering fog. Never a
// NaN or Inf, and where the answer is known it is met:
//   - density ~ 0 (height fog e^(-100), a grid of zeros): the image of the
//     same room without a medium, to 1e-5 relative;
//   - density saturated everywhere (base 1e6, falloff 1e4; the grid at
//     3e38): every surface's view transmittance and every light path 0,
//     so the image is black (< 1e-6);
//   - falloff 1e4 with the base inside the room, dense scattering: finite
//     and non-negative.
#include "toth_test.h"
#include "../reference/vdb_writer.h"

#define N 48
static const double LIGHT[3] = {0.4, 2.2, -0.5}, I[3] = {8, 7, 6};
static char scene[1024], out[1024];

static bool render(const char *medium, st_image *img) {
    toth_write_room(scene, N, LIGHT, I, 0.6, medium, "");
    int rc = st_test_render(scene, out, NULL);
    CHECK(rc == 0, "exit %d for %s", rc, medium ? medium : "no medium");
    return rc == 0 && st_test_read(out, img);
}

static void stats(const st_image *img, double *mx, double *mn) {
    *mx = -INFINITY, *mn = INFINITY;
    for (int j = 0; j < img->height; j++)
        for (int i = 0; i < img->width; i++)
            for (int k = 0; k < 3; k++) {
                double v = st_image_px(img, i, j)[k];
                *mx = fmax(*mx, v), *mn = fmin(*mn, v);
            }
}

// kind: 0 finite and >= 0 only, 1 equal to `clear`, 2 black.
static void run(const char *what, const char *medium, int kind, const st_image *clear) {
    st_image img = {0};
    if (!render(medium, &img)) return;
    double mx, mn;
    stats(&img, &mx, &mn);
    CHECK(st_test_all_finite(&img) && mn >= 0, "%s: finite and >= 0 (min %g)", what, mn);
    double worst = 0;
    if (kind == 1)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++)
                for (int k = 0; k < 3; k++) {
                    double a = st_image_px(&img, i, j)[k], b = st_image_px(clear, i, j)[k];
                    worst = fmax(worst, fabs(a - b) / fmax(b, 1e-6));
                }
    printf("  %-34s max %.4g, min %.4g", what, mx, mn);
    if (kind == 1) printf(", worst relative difference to no medium %.2g", worst);
    printf("\n");
    if (kind == 1) CHECK(worst <= 1e-5, "%s: differs from no medium by %g", what, worst);
    if (kind == 2) CHECK(mx < 1e-6, "%s: max %g, expected black", what, mx);
    st_image_free(&img);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/stress.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/stress.exr", ST_TEST_SCRATCH);
    char vdb[1024];
    st_image clear = {0};
    if (!render(NULL, &clear)) return st_test_summary("test_toth_density_stress");
    const char *m = "\"sigma_s\": [0.5, 0.5, 0.5], \"sigma_a\": [0.1, 0.1, 0.1], \"density\": ";
    char med[512];
#define MED(d) (snprintf(med, sizeof med, "%s%s", m, d), med)
    run("height fog e^(-100)", MED("{\"height\": {\"base\": -1e6, \"falloff\": 1e-4}}"), 1, &clear);
    run("height fog, falloff 1e4 at y = 1", MED("{\"height\": {\"base\": 1, \"falloff\": 1e4}}"), 0,
        NULL);
    run("height fog saturated (base 1e6)", MED("{\"height\": {\"base\": 1e6, \"falloff\": 1e4}}"),
        2, NULL);
    run("dense fog, sigma_s 1e4",
        "\"sigma_s\": [1e4, 1e4, 1e4], \"sigma_a\": [0, 0, 0], \"density\": {\"height\": "
        "{\"base\": 1, \"falloff\": 2}}",
        0, NULL);
    // Grids filling the room: 8^3 voxels of 0.6 m centred on it.
    snprintf(vdb, sizeof vdb, "%s/zero.vdb", ST_TEST_SCRATCH);
    st_test_vdb spec = {.name = "density", .n = {8, 8, 8}, .origin = {-4, 0, -4}, .voxel = 0.6};
    spec.single_grid = true;
    CHECK(st_test_write_vdb(vdb, &spec), "writing %s", vdb);
    run("grid of zeros", MED("{\"vdb\": \"zero.vdb\"}"), 1, &clear);
    snprintf(vdb, sizeof vdb, "%s/huge.vdb", ST_TEST_SCRATCH);
    spec.value = 3e38f, spec.n[0] = spec.n[1] = spec.n[2] = 12, spec.origin[0] = -6,
    spec.origin[1] = -2, spec.origin[2] = -6;
    CHECK(st_test_write_vdb(vdb, &spec), "writing %s", vdb);
    run("grid of 3e38", MED("{\"vdb\": \"huge.vdb\"}"), 2, NULL);
    st_image_free(&clear);
    return st_test_summary("test_toth_density_stress");
}
