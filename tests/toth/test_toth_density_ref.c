// toth marching a varying density (march_density.glsl) against strahl
// reference, which tracks the same media by ratio tracking and never uses
// the closed forms: a height-fog room lit by a point light out of view (the closed-form
// light and view paths) and a soft OpenVDB cloud lit by a spot above a
// floor (the grid's DDA, the cloud's shadow and self-shadowing). Both at
// 64x48 on the point filter (pixel centres; the default box filter would
// need the jittered accumulation on one side and the pixel integral on
// the other), toth at its defaults. Asserted: the image means agree within
// 1.5% and the debiased NRMSE (the reference's own noise removed with its
// stderr channels) is at most 0.02 (height fog) and 0.05 (the cloud, issue
// 24's bound for toth). Measured at 256 spp: height fog 0.01% / 0.0051,
// cloud 0.01% / 0.034. A point light in view is left out: the uniform
// march's bounded 1/d^2 near it (toth_min_d2) puts a single pixel off by
// far more than the rest (README.md, known limits).
#include "toth_test.h"
#include "../reference/vdb_writer.h"

static const char *dir = ST_TEST_SCRATCH;

static void check(const char *name, const char *json, double mean_tol, double nrmse_tol) {
    char scene[1024], gpu[1024], ref[1024];
    snprintf(scene, sizeof scene, "%s/%s.json", dir, name);
    snprintf(gpu, sizeof gpu, "%s/%s.gpu.exr", dir, name);
    snprintf(ref, sizeof ref, "%s/%s.ref.exr", dir, name);
    st_test_write(scene, json);
    CHECK(st_test_render(scene, gpu, NULL) == 0, "%s: render", name);
    CHECK(st_test_sh("%s reference %s -o %s --spp 128 --steps 16 --bounces 0 --seed 3 --filter "
                     "point >/dev/null",
                     ST_TEST_STRAHL, scene, ref) == 0,
          "%s: reference", name);
    st_image a = {0}, b = {0}, s = {0};
    static const char *const rgb[] = {"R", "G", "B"};
    static const char *const se[] = {"stderr.R", "stderr.G", "stderr.B"};
    st_err err = {0};
    if (!st_test_read(gpu, &a) || !st_image_read_exr_channels(ref, rgb, 3, &b, &err) ||
        !st_image_read_exr_channels(ref, se, 3, &s, &err)) {
        CHECK(0, "%s: reading the images: %s", name, err.msg);
        return;
    }
    CHECK(st_test_all_finite(&a), "%s: finite", name);
    st_metrics m;
    if (st_image_compare_noisy(&a, &b, &s, &m, &err)) {
        double ratio = m.mean_a[3] / m.mean_b[3], nrmse = m.rmse_debiased[3] / m.mean_b[3];
        printf("  %-10s mean %.5g (reference %.5g, ratio %.4f), NRMSE %.4f debiased (%.4f raw)\n",
               name, m.mean_a[3], m.mean_b[3], ratio, nrmse, m.rmse[3] / m.mean_b[3]);
        CHECK(fabs(ratio - 1) <= mean_tol, "%s: mean ratio %.4f", name, ratio);
        CHECK(nrmse <= nrmse_tol, "%s: debiased NRMSE %.4f > %.4f", name, nrmse, nrmse_tol);
    } else {
        CHECK(0, "%s: %s", name, err.msg);
    }
    st_image_free(&a), st_image_free(&b), st_image_free(&s);
}

int main(void) {
    check("height",
          "{\"image\": {\"width\": 64, \"height\": 48},\n"
          " \"camera\": {\"position\": [0, 1.4, 2.7], \"target\": [0.3, 1.2, -1], \"fov_y\": 65},\n"
          " \"lights\": [{\"type\": \"point\", \"position\": [0.5, 2.9, 1.5], \"intensity\": [6, "
          "5, 4]}],\n"
          " \"geometry\": [{\"box\": {\"min\": [-3, 0, -3], \"max\": [3, 3, 3]}, \"inward\": "
          "true, \"albedo\": [0.6, 0.6, 0.6]},\n"
          "  {\"box\": {\"min\": [-0.2, 0, -1.4], \"max\": [0.4, 1.1, -0.8]}, \"albedo\": [0.5, "
          "0.4, 0.3]}],\n"
          " \"medium\": {\"sigma_s\": [0.3, 0.3, 0.3], \"sigma_a\": [0.05, 0.05, 0.05], "
          "\"phase\": {\"hg\": 0.3}, \"density\": {\"height\": {\"base\": 0.2, \"falloff\": "
          "1.1}}},\n"
          " \"modules\": [{\"name\": \"shadow_map\"}, {\"name\": \"toth\"}]}\n",
          0.015, 0.02);
    char vdb[1024];
    snprintf(vdb, sizeof vdb, "%s/cloud.vdb", dir);
    st_test_vdb spec = {.name = "density",
                        .n = {16, 16, 16},
                        .origin = {-8, -8, -8},
                        .value = 1.0f,
                        .voxel = 0.075,
                        .radius = 7.5,
                        .single_grid = true};
    CHECK(st_test_write_vdb(vdb, &spec), "writing %s", vdb);
    check("cloud",
          "{\"image\": {\"width\": 64, \"height\": 48},\n"
          " \"camera\": {\"position\": [0.3, 1.5, 3.4], \"target\": [0, 0.9, -0.5], \"fov_y\": "
          "55},\n"
          " \"lights\": [{\"type\": \"spot\", \"position\": [0.2, 3, 0], \"direction\": [-0.05, "
          "-1, -0.15], \"intensity\": [30, 28, 24], \"inner_angle\": 18, \"outer_angle\": 28}],\n"
          " \"geometry\": [{\"box\": {\"min\": [-2.5, -0.1, -2.5], \"max\": [2.5, 0, 2.5]}, "
          "\"albedo\": [0.6, 0.55, 0.5]},\n"
          "  {\"box\": {\"min\": [-2.5, 0, -1.6], \"max\": [2.5, 3, -1.5]}, \"albedo\": [0.6, "
          "0.6, 0.6]}],\n"
          " \"medium\": {\"sigma_s\": [2.7, 2.7, 2.7], \"sigma_a\": [0.3, 0.3, 0.3], \"phase\": "
          "{\"hg\": 0.4}, \"density\": {\"vdb\": \"cloud.vdb\", \"transform\": {\"translate\": "
          "[0.1, 1.3, -0.3]}}},\n"
          " \"modules\": [{\"name\": \"shadow_map\"}, {\"name\": \"toth\"}]}\n",
          0.015, 0.05);
    return st_test_summary("test_toth_density_ref");
}
