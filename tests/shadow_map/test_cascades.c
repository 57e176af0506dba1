// Directional shadows (shadow_map's cascades) against the reference's exact
// shadow rays, and the cascades' caching under camera moves.
//
// Bound: a ground point is classed from the texel its light-space projection
// falls in (nearest sampling), so a wrong class needs the shadow outline
// within half a texel diagonal (t / sqrt 2) of the projection, plus the bias
// (b = t (bias + slope tan i) along the light) near contacts. With the fit's
// margin a texel is t <= 2.4 R / res, R the bounding radius of the whole
// view frustum up to the scene's far end (any slice is smaller). On the
// ground (normal +y) a light-space distance s is at most s / L.y, so every
// misclassified ground pixel must have a reference class change within
// k = 1 + ceil((t / sqrt 2 + b) / (L.y f)) pixels, f the pixel's footprint.
#include "st_test_render.h"
#include "st_gl.h"
#include "st_world.h"

enum { W = 128, H = 96, RES = 1024 };
static const double CAM[3] = {0, 3, 6}, TGT[3] = {0, 0, -1}, UP[3] = {0, 1, 0}, FOV = 50;
static const double SUN[3] = {0.6, -0.7, 0.2}, E = 2.0, RHO = 0.6;
static const double BOXES[2][2][3] = {{{-0.8, 0, -0.6}, {0.4, 2, 0.2}},
                                      {{-3, 0, -3.5}, {-1.5, 1.5, -2}}};

static void write_scene(const char *path, const double cam[3], const double tgt[3]) {
    char json[4096];
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": %d, \"height\": %d},\n"
        " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, 0],"
        " \"fov_y\": %g, \"near\": 0.05, \"far\": 100},\n"
        " \"lights\": [{\"type\": \"directional\", \"direction\": [%g, %g, %g], \"irradiance\": "
        "[%g, %g, %g]}],\n"
        " \"geometry\": [{\"quad\": {\"corner\": [-6, 0, -6], \"u\": [0, 0, 12], \"v\": [12, 0, "
        "0]}, \"albedo\": [%g, %g, %g]},\n"
        "  {\"box\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}},\n"
        "  {\"box\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}}],\n"
        " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"cascade_resolution\": %d}}]}\n",
        W, H, cam[0], cam[1], cam[2], tgt[0], tgt[1], tgt[2], FOV, SUN[0], SUN[1], SUN[2], E, E, E,
        RHO, RHO, RHO, BOXES[0][0][0], BOXES[0][0][1], BOXES[0][0][2], BOXES[0][1][0],
        BOXES[0][1][1], BOXES[0][1][2], BOXES[1][0][0], BOXES[1][0][1], BOXES[1][0][2],
        BOXES[1][1][0], BOXES[1][1][1], BOXES[1][1][2], RES);
    st_test_write(path, json);
}

static int lit(const st_image *img, int i, int j) {
    return st_image_px(img, i, j)[0] > 0;
}

int main(void) {
    char scene[512], gpu[512], ref[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/sun.json", ST_TEST_SCRATCH);
    snprintf(gpu, sizeof gpu, "%s/sun_gpu.exr", ST_TEST_SCRATCH);
    snprintf(ref, sizeof ref, "%s/sun_ref.exr", ST_TEST_SCRATCH);
    write_scene(scene, CAM, TGT);
    CHECK(st_test_render(scene, gpu, NULL) == 0, "render");
    snprintf(cmd, sizeof cmd, "%s reference %s -o %s --bounces 0 --spp 1 --filter point 2>&1",
             ST_TEST_STRAHL, scene, ref);
    static char buf[1 << 14];
    CHECK(st_test_capture(buf, sizeof buf, cmd) == 0, "reference: %s", buf);
    st_image a = {0}, b = {0};
    if (!st_test_read(gpu, &a) || !st_test_read(ref, &b)) return st_test_summary("test_cascades");

    double sl = sqrt(SUN[0] * SUN[0] + SUN[1] * SUN[1] + SUN[2] * SUN[2]), Ly = -SUN[1] / sl;
    double tan_i = sqrt(1 - Ly * Ly) / Ly;
    // R: the frustum from the camera to the scene's far end (depth <= 13 m here).
    double th = tan(FOV * M_PI / 360), zf = 13.0,
           R = zf * sqrt(1 + th * th * (1 + (double)W * W / (H * H)));
    double t = 2.4 * R / RES, bias = t * (1.0 + 1.0 * tan_i);
    st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, W, H);
    int ground = 0, shadowed = 0, wrong = 0, outside = 0, kmax = 0;
    double worst = 0;
    for (int j = 1; j < H - 1; j++)
        for (int i = 1; i < W - 1; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            if (d[1] >= -1e-3) continue;
            double tg = -CAM[1] / d[1];
            int blocked = 0;
            for (int k = 0; k < 2; k++) {
                double tb = st_test_ray_box(CAM, d, BOXES[k][0], BOXES[k][1]);
                blocked |= tb >= 0 && tb < tg;
            }
            double p[3] = {CAM[0] + tg * d[0], 0, CAM[2] + tg * d[2]};
            if (blocked || fabs(p[0]) > 5.9 || fabs(p[2]) > 5.9) continue;
            ground++;
            int ra = lit(&a, i, j), rb = lit(&b, i, j);
            shadowed += !rb;
            if (ra && rb)
                worst = fmax(worst, fabs(st_image_px(&a, i, j)[0] - st_image_px(&b, i, j)[0]) /
                                        st_image_px(&b, i, j)[0]);
            if (ra == rb) continue;
            wrong++;
            // This pixel's footprint on the ground and its allowed distance to an edge.
            double f = tg * 2 * th / H / fabs(d[1]);
            int k = 1 + (int)ceil((t / sqrt(2.0) + bias) / (Ly * f));
            kmax = k > kmax ? k : kmax;
            int near_edge = 0;
            for (int y = j - k; y <= j + k && !near_edge; y++)
                for (int x = i - k; x <= i + k && !near_edge; x++)
                    if (x >= 0 && y >= 0 && x < W && y < H) near_edge = lit(&b, x, y) != rb;
            outside += !near_edge;
        }
    printf("  %d ground pixels, %d in shadow; %d classed differently from the exact shadow rays, "
           "%d of them "
           "farther than the bound (k <= %d px; texel <= %.3g m); lit pixels within %.2e\n",
           ground, shadowed, wrong, outside, kmax, t, worst);
    CHECK(ground > 5000 && shadowed > 300, "%d ground pixels, %d shadowed", ground, shadowed);
    CHECK(outside == 0, "%d misclassified pixels beyond the derived bound", outside);
    CHECK(wrong < 0.03 * shadowed, "%d misclassified of %d shadowed", wrong, shadowed);
    CHECK(worst < 0.01, "lit pixels: worst relative error %.4f", worst);
    st_image_free(&a);
    st_image_free(&b);

    // Caching: a static camera renders the cascades once; a move of 1 cm
    // stays inside every fitted margin and re-renders none; a move of 3 m
    // leaves them and re-renders.
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    st_scene sc = {0};
    st_world *w = ctx && st_scene_load(scene, &sc, &err) ? st_world_create(&sc, NULL, &err) : NULL;
    CHECK(w != NULL, "world: %s", err.msg);
    if (w) {
        unsigned runs[4] = {0};
        const float up[3] = {0, 1, 0}, tg[3] = {(float)TGT[0], (float)TGT[1], (float)TGT[2]};
        const float poses[4][3] = {{0, 3, 6}, {0, 3, 6}, {0.01f, 3, 6}, {3, 3, 6}};
        for (int k = 0; k < 4 && w; k++) {
            st_world_set_camera(w, poses[k], tg, up);
            CHECK(st_world_frame(w, &err), "frame: %s", err.msg);
            for (int i = 0; i < st_world_num_pass_stats(w); i++) {
                const st_pass_stats *ps = st_world_pass_stats(w, i);
                if (!strcmp(ps->module, "shadow_map")) runs[k] = ps->runs;
            }
        }
        printf("  cascade renders after frames: %u %u %u %u (static, static, 1 cm, 3 m)\n", runs[0],
               runs[1], runs[2], runs[3]);
        CHECK(runs[0] == 1 && runs[1] == 1 && runs[2] == 1 && runs[3] == 2,
              "cascade renders %u %u %u %u", runs[0], runs[1], runs[2], runs[3]);
        st_world_destroy(w);
    }
    st_scene_free(&sc);
    st_context_destroy(ctx);
    return st_test_summary("test_cascades");
}
