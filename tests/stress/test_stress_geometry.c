// Geometry stress: degenerate and zero-area triangles (a glTF written here,
// with and without NORMAL), a singular node transform, flipped normals (a
// box seen from inside with its faces outward: every back side is black),
// empty geometry, a 1x1 image, and zero-area JSON shapes (refused). Every
// module configuration renders each case with every value finite; the CPU
// reference renders them at 2 spp.
#include "stress.h"

enum { N = 32 };

// Camera looking down at the floor y = 0 from (0, 2, 1.6), a wall behind it
// (z = -1, for the indirect-light modules to bounce light off the floor);
// light above the floor.
static const double CAM[3] = {0, 2, 1.6}, TGT[3] = {0, 0, 0}, UP[3] = {0, 1, 0}, FOV = 60;
static const double LIGHT[3] = {0.2, 1.2, 0.1}, INTENSITY = 2, RHO = 0.5;

static char json[16384], tail[1024];

static void floor_scene(const char *gltf, const stress_config *c) {
    stress_config_tail(tail, sizeof tail, c);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g},"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],"
             " \"geometry\": [{\"gltf\": \"%s\", \"albedo\": [%g, %g, %g]},"
             "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [2, 0, 0], \"v\": [0, 2, 0]}}],%s",
             N, N, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], FOV, LIGHT[0], LIGHT[1],
             LIGHT[2], INTENSITY, INTENSITY, INTENSITY, gltf, RHO, RHO, RHO, tail);
}

// Largest relative error of the analytic floor radiance over pixels that see
// the floor (|x|, |z| < 0.95, away from the edges).
static double floor_error(const st_image *img) {
    st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, N, N);
    const double q[3] = {0, 0, 0}, n[3] = {0, 1, 0};
    double worst = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double t, d[3];
            double want = stress_plane_direct(&c, i, j, q, n, RHO, LIGHT, INTENSITY, &t);
            st_test_ray(&c, i, j, d);
            double x = c.pos[0] + t * d[0], z = c.pos[2] + t * d[2];
            if (!(t > 0) || fabs(x) > 0.95 || fabs(z) > 0.95) continue;
            worst = fmax(worst, fabs(st_image_px(img, i, j)[0] - want) / want);
        }
    return worst;
}

// The floor (two good triangles, [-1,1]^2 at y = 0) plus degenerate ones
// lifted to y = 0.5, where they would be seen if they were rasterized.
static const float POS[][3] = {
    {-1, 0, -1},
    {1, 0, -1},
    {1, 0, 1},
    {-1, 0, 1},         // 0-3 floor
    {0.1f, 0.5f, 0.1f}, // 4 a point
    {0.2f, 0.5f, 0.3f},
    {0.4f, 0.5f, 0.3f},
    {0.7f, 0.5f, 0.3f}, // 5-7 collinear
    {-0.5f, 0.5f, 0},
    {-0.5f + 1e-7f, 0.5f, 0},
    {-0.5f, 0.5f, 1e-7f}, // 8-10 area 5e-15
    {-1, 0.3f, 0.4321f},
    {1, 0.3f, 0.4321f},
    {1, 0.3f, 0.4321001f}, // 11-13 needle
    {5, 0.5f, 5},
    {5, 0.5f, 5},
    {5, 0.5f, 5}, // 14-16 three equal vertices
};
static const uint32_t IDX[] = {
    0,  3,  2,  0, 2, 1, // floor, facing +y
    4,  4,  4,           // all indices equal
    4,  4,  5,           // two equal
    5,  6,  7,  7, 6, 5, // collinear, both windings
    8,  9,  10,          // tiny
    11, 12, 13,          // needle, 2 m by 1e-7 m
    14, 15, 16,          // equal positions, distinct indices
};
#define NV ((uint32_t)(sizeof POS / sizeof POS[0]))
#define NI ((uint32_t)(sizeof IDX / sizeof IDX[0]))

static void test_degenerate(void) {
    // Normals: +y for the floor, zero vectors for the degenerate vertices
    // (the loader must not normalize them into NaN).
    float nrm[NV][3] = {{0}};
    for (int v = 0; v < 4; v++)
        nrm[v][1] = 1;
    char path[512], name[64];
    const char *variants[] = {"floor", "degenerate_normals", "degenerate_flat", "singular_scale"};
    st_image base[STRESS_NUM_CONFIGS] = {{0}};
    for (int k = 0; k < 4; k++) {
        snprintf(path, sizeof path, "%s/%s.glb", ST_TEST_SCRATCH, variants[k]);
        // The flat variant has no NORMAL: the loader computes face normals,
        // which a zero-area triangle does not have. The singular variant
        // squashes y (the floor is in y = 0 already, so it must look the same).
        int ok = k == 0   ? stress_write_glb(path, &POS[0][0], &nrm[0][0], 4, IDX, 6, NULL)
                 : k == 1 ? stress_write_glb(path, &POS[0][0], &nrm[0][0], NV, IDX, NI, NULL)
                 : k == 2 ? stress_write_glb(path, &POS[0][0], NULL, NV, IDX, NI, NULL)
                          : stress_write_glb(path, &POS[0][0], &nrm[0][0], 4, IDX, 6,
                                             ", \"scale\": [1, 0, 1]");
        CHECK(ok, "write %s", path);
        snprintf(path, sizeof path, "%s.glb", variants[k]);
        for (int m = 0; m < STRESS_NUM_CONFIGS; m++) {
            const stress_config *c = &stress_configs[m];
            floor_scene(path, c);
            snprintf(name, sizeof name, "%s_%s", variants[k], c->name);
            st_image img = {0};
            if (!stress_render(name, json, NULL, &img)) continue;
            stress_stats s = stress_image_stats(&img);
            CHECK(s.negative == 0 && s.lit > 0, "%s: %zu negative, %zu lit values", name,
                  s.negative, s.lit);
            if (c->direct) {
                double e = floor_error(&img);
                printf("  %-32s floor error %.2e\n", name, e);
                CHECK(e < 0.01, "%s: floor radiance off by %.3g (relative)", name, e);
            }
            if (k == 0) {
                base[m] = img;
                continue;
            }
            // Degenerate triangles produce no fragments and the squashed
            // floor is the floor: the same image as the floor alone.
            double d = stress_rel_l1(&img, &base[m]);
            printf("  %-32s differs from the floor alone by %.2e\n", name, d);
            CHECK(d < 1e-4, "%s: relative L1 difference from the floor alone %.3g", name, d);
            st_image_free(&img);
        }
        // The CPU reference's direct light: exact for a point light.
        snprintf(name, sizeof name, "%s_reference", variants[k]);
        floor_scene(path, &stress_configs[0]);
        st_image ref = {0};
        if (stress_ok("reference", name, json, "--spp 2 --seed 1 --aov direct", &ref)) {
            double e = floor_error(&ref);
            printf("  %-32s floor error %.2e\n", name, e);
            CHECK(e < 0.01, "%s: floor radiance off by %.3g (relative)", name, e);
        }
        st_image_free(&ref);
    }
    for (int m = 0; m < STRESS_NUM_CONFIGS; m++)
        st_image_free(&base[m]);
}

// A box [-1,1] x [0,2] x [-1,1] seen from inside.
static const double BOX_CAM[3] = {0, 1, 0.6}, BOX_TGT[3] = {0, 1, -1}, BOX_FOV = 70;
static const double BOX_LIGHT[3] = {0.3, 1.6, 0.2};

static void box_scene(const char *flags, const stress_config *c) {
    stress_config_tail(tail, sizeof tail, c);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g},"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],"
             " \"geometry\": [{\"box\": {\"min\": [-1, 0, -1], \"max\": [1, 2, 1]}, \"albedo\": "
             "[%g, %g, %g]%s}],%s",
             N, N, BOX_CAM[0], BOX_CAM[1], BOX_CAM[2], BOX_TGT[0], BOX_TGT[1], BOX_TGT[2], BOX_FOV,
             BOX_LIGHT[0], BOX_LIGHT[1], BOX_LIGHT[2], INTENSITY, INTENSITY, INTENSITY, RHO, RHO,
             RHO, flags, tail);
}

// Analytic radiance of the back wall z = -1 at pixel (i, j) of a w x h image.
static double back_wall(int w, int h, int i, int j) {
    st_test_cam c = st_test_camera(BOX_CAM, BOX_TGT, UP, BOX_FOV, w, h);
    const double q[3] = {0, 0, -1}, n[3] = {0, 0, 1};
    double t;
    return stress_plane_direct(&c, i, j, q, n, RHO, BOX_LIGHT, INTENSITY, &t);
}

static void test_flipped(void) {
    char name[64];
    for (int m = 0; m < STRESS_NUM_CONFIGS; m++) {
        const stress_config *c = &stress_configs[m];
        st_image in = {0}, out = {0}, two = {0};
        box_scene(", \"inward\": true", c);
        snprintf(name, sizeof name, "box_inward_%s", c->name);
        int ok_in = stress_render(name, json, NULL, &in);
        box_scene("", c);
        snprintf(name, sizeof name, "box_outward_%s", c->name);
        int ok_out = stress_render(name, json, NULL, &out);
        box_scene(", \"double_sided\": true", c);
        snprintf(name, sizeof name, "box_double_sided_%s", c->name);
        int ok_two = stress_render(name, json, NULL, &two);
        if (ok_out) {
            // Only back sides are in view: no direct, emitted or indirect
            // light, and nothing for the medium modules to add but in-scatter.
            stress_stats s = stress_image_stats(&out);
            if (!c->medium)
                CHECK(s.max == 0, "%s: outward box from inside: max radiance %g, want 0", c->name,
                      s.max);
            CHECK(s.negative == 0, "%s: %zu negative values", c->name, s.negative);
        }
        if (ok_in && c->direct) {
            double want = back_wall(N, N, N / 2, N / 2), got = st_image_px(&in, N / 2, N / 2)[0];
            printf("  box_inward_%-20s back wall %.6g (analytic %.6g)\n", c->name, got, want);
            CHECK_REL(got, want, 0.01, 0);
        }
        if (ok_in && ok_two) {
            // Outward faces shown from both sides light up like inward ones
            // (atlas_gi: the same up to its sampling noise).
            double d = stress_rel_l1(&two, &in);
            double ma = stress_image_stats(&two).mean, mb = stress_image_stats(&in).mean;
            printf("  box_double_sided_%-14s differs from inward by %.2e, mean %.6g vs %.6g\n",
                   c->name, d, ma, mb);
            if (strcmp(c->name, "atlas_gi") != 0)
                CHECK(d < 1e-3, "%s: double-sided outward vs inward: relative L1 %.3g", c->name, d);
            CHECK_REL(ma, mb, 0.03, 0);
        }
        st_image_free(&in);
        st_image_free(&out);
        st_image_free(&two);
    }
    // The reference agrees that the back sides are black.
    st_image ref = {0};
    box_scene("", &stress_configs[0]);
    if (stress_ok("reference", "box_outward_reference", json, "--spp 2 --seed 1", &ref)) {
        stress_stats s = stress_image_stats(&ref);
        CHECK(s.max == 0, "reference: outward box from inside: max radiance %g, want 0", s.max);
    }
    st_image_free(&ref);
}

static void test_empty(void) {
    char name[64];
    for (int m = 0; m < STRESS_NUM_CONFIGS; m++) {
        const stress_config *c = &stress_configs[m];
        stress_config_tail(tail, sizeof tail, c);
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": %d, \"height\": %d},"
                 " \"camera\": {\"position\": [0, 1, 2], \"target\": [0, 1, 0], \"fov_y\": 50},"
                 " \"lights\": [{\"type\": \"point\", \"position\": [0, 1, 0], \"intensity\": [5, "
                 "5, 5]}],"
                 " \"geometry\": [],%s",
                 N, N, tail);
        snprintf(name, sizeof name, "empty_%s", c->name);
        st_image img = {0};
        if (stress_render(name, json, NULL, &img)) {
            stress_stats s = stress_image_stats(&img);
            printf("  %-32s max %.4g\n", name, s.max);
            // Without a medium nothing can send light to the camera.
            if (!c->medium) CHECK(s.max == 0, "%s: max %g, want 0", name, s.max);
            CHECK(s.negative == 0, "%s: %zu negative values", name, s.negative);
        }
        st_image_free(&img);
    }
    // No geometry, no lights, no modules keys at all.
    st_image img = {0};
    const char *bare =
        "{\"image\": {\"width\": 8, \"height\": 8},"
        " \"camera\": {\"position\": [0, 0, 1], \"target\": [0, 0, 0], \"fov_y\": 40}}";
    if (stress_render("bare", bare, NULL, &img))
        CHECK(stress_image_stats(&img).max == 0, "bare scene is black");
    st_image_free(&img);
    if (stress_ok("reference", "bare_reference", bare, "--spp 1", &img))
        CHECK(stress_image_stats(&img).max == 0, "bare scene is black in the reference");
    st_image_free(&img);
}

static void test_one_pixel(void) {
    char name[64];
    double want = back_wall(1, 1, 0, 0);
    for (int m = 0; m < STRESS_NUM_CONFIGS; m++) {
        const stress_config *c = &stress_configs[m];
        box_scene(", \"inward\": true", c);
        snprintf(name, sizeof name, "one_pixel_%s", c->name);
        st_image img = {0};
        if (stress_render(name, json, "--size 1x1", &img)) {
            CHECK(img.width == 1 && img.height == 1, "%s: %dx%d", name, img.width, img.height);
            double got = img.data[0];
            printf("  %-32s %.6g (analytic direct %.6g)\n", name, got, want);
            if (c->direct)
                CHECK_REL(got, want, 0.01, 0);
            else
                CHECK(got >= 0, "%s: negative radiance %g", name, got);
        }
        st_image_free(&img);
    }
}

static void test_refused(void) {
    // Zero-area JSON shapes are refused with their key path.
    const char *head =
        "{\"image\": {\"width\": 8, \"height\": 8},"
        " \"camera\": {\"position\": [0, 1, 2], \"target\": [0, 1, 0], \"fov_y\": 50},"
        " \"geometry\": [{\"box\": {\"min\": [-1, 0, -1], \"max\": [1, 2, 1]}}, ";
    snprintf(json, sizeof json,
             "%s{\"quad\": {\"corner\": [0, 0, 0], \"u\": [1, 0, 0], \"v\": [2, 0, 0]}}]}", head);
    stress_refused("render", "quad_parallel", json, NULL, "geometry[1].quad");
    snprintf(json, sizeof json,
             "%s{\"quad\": {\"corner\": [0, 0, 0], \"u\": [0, 0, 0], \"v\": [1, 0, 0]}}]}", head);
    stress_refused("render", "quad_zero_edge", json, NULL, "geometry[1].quad.u");
    snprintf(json, sizeof json, "%s{\"box\": {\"min\": [0, 0, 0], \"max\": [1, 0, 1]}}]}", head);
    stress_refused("render", "box_flat", json, NULL, "geometry[1].box");
    snprintf(json, sizeof json, "%s{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 0}}]}", head);
    stress_refused("render", "sphere_zero", json, NULL, "geometry[1].sphere.radius");
    snprintf(json, sizeof json, "%s{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 0}}]}", head);
    stress_refused("reference", "sphere_zero_reference", json, "--spp 1",
                   "geometry[1].sphere.radius");
}

int main(void) {
    double t0 = stress_now();
    test_degenerate();
    test_flipped();
    test_empty();
    test_one_pixel();
    test_refused();
    printf("  %.1f s\n", stress_now() - t0);
    return st_test_summary("test_stress_geometry");
}
