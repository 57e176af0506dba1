// The precomputed transfer (mode=transfer, the default):
//   - form-factor oracles (docs/physics.md) within 1%: perpendicular unit squares
//     sharing an edge (0.200044), parallel unit squares at distance 1
//     (0.199825), a point under a coaxial disk, R^2 / (R^2 + h^2);
//   - a Cornell box against `strahl reference --bounces N --aov indirect` (1 and 3):
//     noise-corrected relMSE over 8x8 pixel blocks (gi_refcmp.h), with the
//     reference's own noise asserted to be far below the bound; the same
//     in an absorbing medium (extinction along every sender-receiver segment);
//   - camera invariance: a camera move reruns no atlas pass, and world
//     points look the same from two poses;
//   - relighting: moving the light gives exactly the image a fresh world
//     with the light there gives;
//   - a box face toward the camera with no direct light on it receives the
//     floor's indirect light (compared with the reference).
#include "gi_world.h"
#include "st_test_support.h"
#include "gi_refcmp.h"

#define RHO 0.5
#define H 96
#define K 80

static void square_oracles(void) {
    static const struct {
        const char *name;
        double F, D;
        const char *emitter;
    } cf[2] = {
        {"perpendicular", 0.200044, 3.0,
         "\"corner\": [0, 0, 0], \"u\": [1, 0, 0], \"v\": [0, 1, 0]"},
        {"parallel", 0.199825, 0.9, "\"corner\": [0, 1, 0], \"u\": [1, 0, 0], \"v\": [0, 0, 1]"},
    };
    for (int c = 0; c < 2; c++) {
        static char json[4096];
        char cam[512];
        gi_headon_camera(cam, sizeof cam, H, K, cf[c].D);
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": %d, \"height\": %d}, %s, \"lights\": [],\n"
                 " \"geometry\": [\n"
                 "  {\"quad\": {\"corner\": [0, 0, 0], \"u\": [0, 0, 1], \"v\": [1, 0, 0]}, "
                 "\"albedo\": [%g, %g, %g]},\n"
                 "  {\"quad\": {%s}, \"albedo\": [0, 0, 0], \"emission\": [1, 1, 1]}],\n"
                 " \"modules\": [{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, "
                 "\"display\": \"indirect\"}}]}\n",
                 H, H, cam, RHO, RHO, RHO, cf[c].emitter);
        char name[64];
        snprintf(name, sizeof name, "transfer_%s", cf[c].name);
        st_image img = {0};
        if (!gi_render(name, json, NULL, &img)) continue;
        double v = gi_headon_mean(&img, K, 0), want = RHO * cf[c].F;
        printf("%s: transfer %.6f, rho F %.6f (rel %+.4f)\n", cf[c].name, v, want, v / want - 1);
        CHECK_REL(v, want, 0.01, 0);
        st_image_free(&img);
    }
}

// A point under a coaxial disk (an area-matched 256-gon facing down) of
// radius R at height h; the receiver is a unit square, the camera looks at
// its centre, where the value is the point's.
static void disk_oracle(void) {
    const double R = 0.5, h = 0.6;
    enum { NS = 256 };
    static char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 64, \"height\": 64},\n"
             " \"camera\": {\"position\": [0, 0.3, 0], \"target\": [0, 0, 0], \"up\": [0, 0, -1], "
             "\"fov_y\": 20, "
             "\"near\": 0.01, \"far\": 10}, \"lights\": [],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-0.5, 0, -0.5], \"u\": [0, 0, 1], \"v\": "
             "[1, 0, 0]}, "
             "\"albedo\": [%g, %g, %g]}],\n"
             " \"modules\": [{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, "
             "\"display\": \"indirect\"}}]}\n",
             RHO, RHO, RHO);
    gi_world g = {0};
    st_err err = {0};
    if (!st_scene_parse(json, strlen(json), ST_TEST_SCRATCH "/disk.json", &g.scene, &err)) {
        CHECK(0, "scene: %s", err.msg);
        return;
    }
    CHECK(st_test_add_disk(&g.scene, NS, R, h, NULL, &err), "add disk: %s", err.msg);
    st_world_opts o = {.timing = true};
    g.w = st_world_create(&g.scene, &o, &err);
    CHECK(g.w != NULL, "world: %s", err.msg);
    st_image img = {0};
    if (g.w && gi_frame(&g) && gi_read(&g, &img)) {
        double v = 0;
        for (int j = 31; j <= 32; j++)
            for (int i = 31; i <= 32; i++)
                v += st_image_px(&img, i, j)[0] / 4;
        double want = RHO * R * R / (R * R + h * h);
        printf("disk: transfer %.6f, rho R^2/(R^2+h^2) %.6f (rel %+.4f)\n", v, want, v / want - 1);
        CHECK_REL(v, want, 0.01, 0);
    }
    st_image_free(&img);
    gi_world_close(&g);
}

// The Cornell box of scenes/gi_cornell.json at 64 x 64, an atlas of 128,
// `bounces` diffuse bounces.
static void cornell_json(char *out, size_t n, const char *light, const char *extra,
                         const char *display, int bounces) {
    snprintf(out, n,
             "{\"image\": {\"width\": 64, \"height\": 64},\n"
             " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 40, "
             "\"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%s], \"intensity\": [3, 3, 3]}],\n"
             " \"geometry\": [\n" ST_TEST_CORNELL_WALLS
             "  {\"box\": {\"min\": [0.1, 0, -0.1], \"max\": [0.7, 0.6, 0.5]}, \"albedo\": [0.75, "
             "0.75, 0.75]},\n"
             "  {\"box\": {\"min\": [-0.7, 0, -0.7], \"max\": [-0.1, 1.2, -0.1]}, \"albedo\": "
             "[0.75, 0.75, 0.75]}\n"
             " ]%s,\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}},\n"
             "              {\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, "
             "\"display\": \"%s\", \"bounces\": %d}}]}\n",
             light, extra, display, bounces);
}

// relMSE over 8x8 blocks of the transfer's indirect image against the
// reference's with as many bounces, noise-corrected; the reference's noise
// must be < bound / 5. Further bounces iterate the transfer with L0 =
// direct + the previous bounce.
static void against_reference(const char *name, const char *extra, int bounces, double bound) {
    static char json[8192];
    cornell_json(json, sizeof json, "0, 1.9, 0", extra, "indirect", bounces);
    char scene[512], ref[512], img[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/%s.json", ST_TEST_SCRATCH, name);
    snprintf(ref, sizeof ref, "%s/%s_ref.exr", ST_TEST_SCRATCH, name);
    snprintf(img, sizeof img, "%s/%s.exr", ST_TEST_SCRATCH, name);
    st_test_write(scene, json);
    snprintf(cmd, sizeof cmd,
             "%s reference %s -o %s --bounces %d --aov indirect --spp %d --seed 3 --filter point "
             ">/dev/null",
             ST_TEST_STRAHL, scene, ref, bounces, 1024 * bounces);
    CHECK(system(cmd) == 0, "%s", cmd);
    CHECK(st_test_render(scene, img, NULL) == 0, "%s: render", name);
    gi_refcmp m = {0};
    st_err err = {0};
    bool ok = gi_refcmp_files(img, ref, 8, &m, &err);
    CHECK(ok, "%s: %s", name, err.msg);
    if (!ok) return;
    printf("%s: relMSE (8x8 blocks, noise-corrected) %.5f (raw %.5f, reference noise %.5f), NRMSE "
           "%.4f, mean %.5f vs "
           "%.5f\n",
           name, m.relmse, m.relmse_raw, m.noise_relmse, m.nrmse, m.mean_a, m.mean_b);
    CHECK(m.noise_relmse < bound / 5, "%s: the reference's noise %.5f is far below the bound %.4f",
          name, m.noise_relmse, bound);
    CHECK(m.relmse <= bound, "%s: relMSE %.5f <= %.4f", name, m.relmse, bound);
    CHECK_REL(m.mean_a, m.mean_b, 0.05, 0);
}

static double max_rel_diff(const st_image *a, const st_image *b) {
    double worst = 0;
    for (int j = 0; j < a->height; j++)
        for (int i = 0; i < a->width; i++)
            for (int c = 0; c < 3; c++) {
                double x = st_image_px(a, i, j)[c], y = st_image_px(b, i, j)[c];
                worst = fmax(worst, fabs(x - y) / (fabs(y) + 1e-3));
            }
    return worst;
}

static void camera_and_relight(void) {
    static char json[8192], json2[8192];
    cornell_json(json, sizeof json, "0, 1.9, 0", "", "indirect", 1);
    gi_world g;
    if (!gi_world_open(&g, json)) return;
    st_image a = {0}, b = {0}, moved = {0}, fresh = {0};
    gi_pose p0 = {{0, 1, 3.4}, {0, 1, 0}, 40}, p1 = {{0.5, 1.3, 2.6}, {-0.2, 0.9, 0}, 50};
    int ga = -1;
    if (gi_frame(&g) && gi_read(&g, &a)) {
        ga = gi_runs(&g, "atlas_gi", "gather", NULL);
        gi_set_pose(&g, &p1);
        gi_frame(&g);
        gi_read(&g, &b);
        CHECK(gi_runs(&g, "atlas_gi", "gather", NULL) == ga &&
                  gi_runs(&g, "atlas_gi", "gbuffer", NULL) == 1,
              "a camera move reruns no atlas pass");
        // Points on flat parts of the walls, floor and boxes, seen from both poses.
        const double pts[][3] = {{0, 1.5, -1}, {-1, 1.2, 0.3}, {1, 0.8, 0.2},
                                 {0, 2, 0.2},  {-0.3, 0, 0.8}, {0.4, 0.3, 0.5}};
        double worst = 0;
        for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++)
            for (int c = 0; c < 3; c++) {
                double x = gi_sample_point(&a, &p0, pts[k], c),
                       y = gi_sample_point(&b, &p1, pts[k], c);
                if (x < 0 || y < 0) continue;
                worst = fmax(worst, fabs(x - y) / y);
            }
        printf("camera invariance: largest difference at 6 world points %.4f%%\n", 100 * worst);
        CHECK(worst < 0.01,
              "the indirect light at world points does not depend on the camera (%.4f%%)",
              100 * worst);
        // Relight: move the light, compare with a fresh world that starts there.
        gi_set_pose(&g, &p0);
        const float lp[3] = {0.5f, 1.5f, 0.6f}, li[3] = {3, 3, 3};
        st_err err = {0};
        CHECK(st_world_set_light(g.w, 0, lp, li, &err), "move light: %s", err.msg);
        gi_frame(&g);
        gi_read(&g, &moved);
        CHECK(gi_runs(&g, "atlas_gi", "gather", NULL) == ga + 1, "one relight pass after the move");
    }
    gi_world_close(&g);
    cornell_json(json2, sizeof json2, "0.5, 1.5, 0.6", "", "indirect", 1);
    gi_world h;
    if (moved.data && gi_world_open(&h, json2)) {
        if (gi_frame(&h) && gi_read(&h, &fresh)) {
            double d = max_rel_diff(&moved, &fresh), dm = max_rel_diff(&a, &fresh);
            printf("relight: moved light vs fresh world: largest relative difference %.3g (before "
                   "the move: %.3g)\n",
                   d, dm);
            CHECK(d <= 1e-5, "moved light gives the fresh world's image (%.3g)", d);
            CHECK(dm > 0.05, "the move changed the image (%.3g)", dm);
        }
        gi_world_close(&h);
    }
    st_image_free(&a);
    st_image_free(&b);
    st_image_free(&moved);
    st_image_free(&fresh);
}

// A box whose face toward the camera gets no direct light (the light is
// behind it): its indirect light from the lit floor, against the reference.
static void dark_face(void) {
    static char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 64, \"height\": 64},\n"
             " \"camera\": {\"position\": [0, 0.5, 2.5], \"target\": [0, 0.3, 0], \"up\": [0, 1, "
             "0], \"fov_y\": 30, "
             "\"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.2, -1.0], \"intensity\": [4, "
             "4, 4]}],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [-3, 0, -3], \"u\": [0, 0, 6], \"v\": [6, 0, 0]}, "
             "\"albedo\": [0.8, 0.8, 0.8]},\n"
             "  {\"box\": {\"min\": [-0.3, 0, -0.3], \"max\": [0.3, 0.6, 0.3]}, \"albedo\": [0.7, "
             "0.7, 0.7]}]%s,\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}},\n"
             "              {\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 256}}]}\n",
             "");
    char scene[512], ref[512], img[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/dark_face.json", ST_TEST_SCRATCH);
    snprintf(ref, sizeof ref, "%s/dark_face_ref.exr", ST_TEST_SCRATCH);
    snprintf(img, sizeof img, "%s/dark_face.exr", ST_TEST_SCRATCH);
    st_test_write(scene, json);
    snprintf(cmd, sizeof cmd,
             "%s reference %s -o %s --bounces 1 --spp 1024 --seed 5 --filter point >/dev/null",
             ST_TEST_STRAHL, scene, ref);
    CHECK(system(cmd) == 0, "%s", cmd);
    CHECK(st_test_render(scene, img, NULL) == 0, "dark face: render");
    st_image a = {0}, r = {0};
    if (st_test_read(img, &a) && st_test_read(ref, &r)) {
        // Mean over a 6 x 6 block around the projection of the front face's
        // (z = 0.3) centre.
        const double pos[3] = {0, 0.5, 2.5}, tgt[3] = {0, 0.3, 0}, up[3] = {0, 1, 0},
                     x[3] = {0, 0.3, 0.3};
        st_test_cam cam = st_test_camera(pos, tgt, up, 30, 64, 64);
        double d[3], z = 0, sx = 0, sy = 0;
        for (int k = 0; k < 3; k++)
            d[k] = x[k] - cam.pos[k];
        for (int k = 0; k < 3; k++)
            z += d[k] * cam.f[k], sx += d[k] * cam.r[k], sy += d[k] * cam.u[k];
        int ci = (int)((sx / z / (cam.tan_half * cam.aspect) + 1) / 2 * 64),
            cj = (int)((1 - sy / z / cam.tan_half) / 2 * 64);
        double va = 0, vr = 0;
        for (int j = cj - 3; j < cj + 3; j++)
            for (int i = ci - 3; i < ci + 3; i++)
                va += st_image_px(&a, i, j)[0] / 36, vr += st_image_px(&r, i, j)[0] / 36;
        printf("dark face: transfer %.5f, reference %.5f (rel %+.3f)\n", va, vr, va / vr - 1);
        CHECK(vr > 0.002, "the reference lights the face indirectly (%g)", vr);
        CHECK_REL(va, vr, 0.15, 0);
    }
    st_image_free(&a);
    st_image_free(&r);
}

int main(void) {
    setvbuf(stdout, NULL, _IOLBF, 0);
    square_oracles();
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) {
        CHECK(0, "context: %s", err.msg);
        return st_test_summary("test_atlas_gi_transfer");
    }
    disk_oracle();
    against_reference("transfer_cornell", "", 1, 0.005);
    against_reference("transfer_cornell_medium",
                      ", \"medium\": {\"sigma_s\": [0, 0, 0], \"sigma_a\": [0.5, 0.2, 0.05], "
                      "\"phase\": \"isotropic\"}",
                      1, 0.005);
    against_reference("transfer_cornell_3_bounces", "", 3, 0.005);
    camera_and_relight();
    dark_face();
    st_context_destroy(ctx);
    return st_test_summary("test_atlas_gi_transfer");
}
