// shadow_map.refine: with a coarse map (32 texels per cube face) the edge of
// a floating box's shadow on the floor lies where the map's texels put it,
// up to a few pixels off. With refine=true (the default) every floor pixel
// whose centre is lit or shadowed by the exact geometry (a ray to the light,
// the oracle) gets exactly that: shadowed pixels are 0 and lit ones within
// 1% of the closed form, edge pixels included. refine=false
// must disagree somewhere, or the test could not see what refine does.
// The same for a directional light (cascades of 64 texels), with the CPU
// reference's exact shadow rays as the oracle: no pixel lit in one and dark
// in the other.
#include "st_test_support.h"
#include "st_test_render.h"

static const double I = 3.0, LP[3] = {0.4, 1.8, 0.2}, RHO = 0.75;
static const double BMIN[3] = {-0.3, 0.8, -0.3}, BMAX[3] = {0.3, 1.0, 0.3};

// Floor pixels whose value contradicts the exact visibility of their centre.
static int mismatches(const st_test_cam *c, const st_image *img, int *decided) {
    int bad = 0;
    *decided = 0;
    for (int j = 0; j < 96; j++)
        for (int i = 0; i < 96; i++) {
            double d[3];
            st_test_ray(c, i, j, d);
            if (d[1] >= 0 || st_test_ray_box(c->pos, d, BMIN, BMAX) >= 0) continue; // the box
            double t = -c->pos[1] / d[1], p[3];
            for (int k = 0; k < 3; k++)
                p[k] = c->pos[k] + t * d[k];
            if (fabs(p[0]) > 3.9 || fabs(p[2]) > 3.9) continue;
            // Undecided only within 1e-3 of a pixel's footprint of the edge
            // (float rounding of the GPU's position).
            int s = st_test_shadow_state(p, 1e-3 * t * 2 * c->tan_half / 96, LP, BMIN, BMAX);
            if (s < 0) continue;
            (*decided)++;
            double l[3] = {LP[0] - p[0], LP[1] - p[1], LP[2] - p[2]};
            double d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
            double e = RHO / M_PI * I * (l[1] / sqrt(d2)) / d2;
            double v = st_image_px(img, i, j)[0];
            bad += s == 1 ? v != 0.0 : fabs(v - e) > 0.01 * e;
        }
    return bad;
}

static void write_sun(const char *path, const char *params) {
    char json[2048];
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": 96, \"height\": 96},\n"
        " \"camera\": {\"position\": [0, 3, 2.5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
        "\"fov_y\": 60, \"near\": 0.05, \"far\": 100},\n"
        " \"lights\": [{\"type\": \"directional\", \"direction\": [0.4, -1, 0.3], "
        "\"irradiance\": [2, 2, 2]}],\n"
        " \"geometry\": [{\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 0, 8], \"v\": [8, 0, "
        "0]}, \"albedo\": [%g, %g, %g]},\n"
        "   {\"box\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}}],\n"
        " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"cascade_resolution\": 64%s}}]}\n",
        RHO, RHO, RHO, BMIN[0], BMIN[1], BMIN[2], BMAX[0], BMAX[1], BMAX[2], params);
    st_test_write(path, json);
}

// Pixels lit in one image and black in the other.
static int lit_differs(const st_image *a, const st_image *b) {
    int n = 0;
    for (int j = 0; j < a->height; j++)
        for (int i = 0; i < a->width; i++)
            n += (st_image_px(a, i, j)[0] > 0) != (st_image_px(b, i, j)[0] > 0);
    return n;
}

int main(void) {
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/refine.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/refine.exr", ST_TEST_SCRATCH);
    const double cam[3] = {0, 3, 2.5}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    st_test_cam c = st_test_camera(cam, tgt, up, 60, 96, 96);
    static const char *const cases[] = {"", ", \"refine\": false"};
    for (int k = 0; k < 2; k++) {
        char modules[256];
        snprintf(modules, sizeof modules,
                 "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 32%s}}", cases[k]);
        st_test_write_shadow_scene(scene, LP, I, RHO, BMIN, BMAX, modules);
        CHECK(st_test_render(scene, out, NULL) == 0, "render (params '%s')", cases[k]);
        st_image img = {0};
        if (!st_test_read(out, &img)) continue;
        CHECK(st_test_all_finite(&img), "finite");
        int decided, bad = mismatches(&c, &img, &decided);
        printf("shadow_map resolution 32%s: %d of %d floor pixels contradict the exact "
               "visibility\n",
               cases[k], bad, decided);
        CHECK(decided > 5000, "floor pixels decided: %d", decided);
        if (k == 0)
            CHECK(bad == 0, "refine%s: %d pixels off the exact shadow", cases[k], bad);
        else
            CHECK(bad >= 5,
                  "refine=false at 32 texels must miss edges (else the test is blind): %d", bad);
        st_image_free(&img);
    }

    char ref[512], cmd[2048];
    static char buf[1 << 14];
    snprintf(ref, sizeof ref, "%s/refine_sun_ref.exr", ST_TEST_SCRATCH);
    write_sun(scene, "");
    snprintf(cmd, sizeof cmd, "%s reference %s -o %s --bounces 0 --spp 1 --filter point 2>&1",
             ST_TEST_STRAHL, scene, ref);
    CHECK(st_test_capture(buf, sizeof buf, cmd) == 0, "reference: %s", buf);
    st_image exact = {0};
    if (!st_test_read(ref, &exact)) return st_test_summary("test_shadow_refine");
    for (int k = 0; k < 2; k++) {
        write_sun(scene, k ? ", \"refine\": false" : "");
        CHECK(st_test_render(scene, out, NULL) == 0, "render (sun, refine %d)", !k);
        st_image img = {0};
        if (!st_test_read(out, &img)) continue;
        int n = lit_differs(&img, &exact);
        printf("directional light, cascades of 64 texels, refine %s: %d pixels lit in one of "
               "shadow_map and the reference only\n",
               k ? "false" : "true", n);
        if (k)
            CHECK(n >= 5, "sun, refine=false must miss edges (else the test is blind): %d", n);
        else
            CHECK(n == 0, "sun, refine: %d pixels off the exact shadow", n);
        st_image_free(&img);
    }
    st_image_free(&exact);
    return st_test_summary("test_shadow_refine");
}
