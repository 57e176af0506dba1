// GPU plugins converge toward the CPU reference as their sample counts grow:
// toth (march steps) on the window scene, atlas_gi (gather samples) on an
// open room, each against `strahl reference` of the same model.
#include "st_test_render.h"

static double rmse_vs(const char *a, const char *ref) {
    st_image x = {0}, r = {0};
    double e = -1;
    if (st_test_read(a, &x) && st_test_read(ref, &r)) {
        st_metrics m;
        st_err err = {0};
        if (st_image_compare(&x, &r, &m, &err)) e = m.rmse[3];
        CHECK(st_test_all_finite(&x), "%s finite", a);
    }
    st_image_free(&x);
    st_image_free(&r);
    return e;
}

// Renders `scene` at each sample count and asserts the error against `ref`
// falls at every step and by at least `factor` overall.
static void converges(const char *what, const char *scene, const char *ref, const char *fixed,
                      const char *param, const int *n, int count, double factor) {
    double prev = 1e30, first = 0, e = 0;
    for (int k = 0; k < count; k++) {
        char out[600], extra[600];
        snprintf(out, sizeof out, "%s/%s_%d.exr", ST_TEST_SCRATCH, what, n[k]);
        snprintf(extra, sizeof extra, "--size 32x32 %s --set %s=%d", fixed, param, n[k]);
        CHECK(st_test_render(scene, out, extra) == 0, "%s: render %s=%d", what, param, n[k]);
        e = rmse_vs(out, ref);
        fprintf(stderr, "%s: %s=%d rmse %.6g\n", what, param, n[k], e);
        CHECK(e >= 0 && e < prev, "%s: rmse %.6g at %s=%d must be below %.6g", what, e, param, n[k],
              prev);
        if (k == 0) first = e;
        prev = e;
    }
    CHECK(e < factor * first, "%s: rmse falls from %.6g to %.6g, want below %.3g of the first",
          what, first, e, factor);
}

int main(void) {
    char ref[600], scene[600];
    // toth: single scattering with shadow-map visibility vs exact visibility.
    snprintf(ref, sizeof ref, "%s/window_ref.exr", ST_TEST_SCRATCH);
    CHECK(st_test_sh(
              "%s reference %s/scenes/godrays_window.json -o %s --size 32x32 --spp 16 --bounces 0 "
              "--filter point",
              ST_TEST_STRAHL, ST_TEST_SOURCE_DIR, ref) == 0,
          "toth reference");
    snprintf(scene, sizeof scene, "%s/scenes/godrays_window.json", ST_TEST_SOURCE_DIR);
    const int steps[] = {2, 8, 32, 128};
    converges("toth", scene, ref,
              "--set toth.interleave=1 --set toth.sampling=uniform --set toth.resolution=half",
              "toth.samples", steps, 4, 0.4);
    // Equi-angular sampling (the default) starts about 3x closer at 2 steps
    // and meets the floor of shadow-map against exact visibility sooner.
    converges("toth_equiangular", scene, ref, "--set toth.resolution=full", "toth.samples", steps,
              4, 0.5);

    // atlas_gi: one bounce without visibility, one frame per sample count
    // (no progressive accumulation), against the reference's bounce.
    snprintf(scene, sizeof scene, "%s/room.json", ST_TEST_SCRATCH);
    st_test_write(
        scene, "{\"image\": {\"width\": 32, \"height\": 32},\n"
               " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"fov_y\": 40},\n"
               " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.2, 0.3], \"intensity\": "
               "[3, 3, 3]}],\n"
               " \"geometry\": [\n"
               "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 0, 2], \"v\": [2, 0, 0]}},\n"
               "  {\"quad\": {\"corner\": [-1, 2, -1], \"u\": [2, 0, 0], \"v\": [0, 0, 2]}},\n"
               "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [2, 0, 0], \"v\": [0, 2, 0]}},\n"
               "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 2, 0], \"v\": [0, 0, 2]}, "
               "\"albedo\": [0.75, 0.1, 0.1]},\n"
               "  {\"quad\": {\"corner\": [1, 0, -1], \"u\": [0, 0, 2], \"v\": [0, 2, 0]}, "
               "\"albedo\": [0.1, 0.75, 0.1]}],\n"
               " \"modules\": [{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 256, "
               "\"mode\": \"gather\", \"visibility\": false, \"sampling\": \"uniform\", "
               "\"progressive\": false}}]}\n");
    snprintf(ref, sizeof ref, "%s/room_ref.exr", ST_TEST_SCRATCH);
    CHECK(st_test_sh("%s reference %s -o %s --spp 2048 --bounces 1 --bounce-visibility off "
                     "--filter point",
                     ST_TEST_STRAHL, scene, ref) == 0,
          "atlas_gi reference");
    const int samples[] = {4, 32, 256};
    converges("atlas_gi", scene, ref, "", "atlas_gi.samples", samples, 3, 0.4);
    return st_test_summary("test_convergence");
}
