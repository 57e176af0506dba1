// Shadows: floor points whose segment to the light crosses a floating box
// get no direct light with shadow_map, the unshadowed value without it.
#include "st_test_support.h"
#include "st_test_render.h"

static const double I = 3.0, LP[3] = {0, 1.8, 0}, RHO = 0.75;
static const double BMIN[3] = {-0.3, 0.8, -0.3}, BMAX[3] = {0.3, 1.0, 0.3};

int main(void) {
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/shadow.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/shadow.exr", ST_TEST_SCRATCH);
    const double cam[3] = {0, 3, 2.5}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    st_test_cam c = st_test_camera(cam, tgt, up, 60, 96, 96);
    for (int with = 0; with < 2; with++) {
        st_test_write_shadow_scene(
            scene, LP, I, RHO, BMIN, BMAX,
            with ? "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}}" : "");
        CHECK(st_test_render(scene, out, NULL) == 0, "render (shadow_map %d)", with);
        st_image img = {0};
        if (!st_test_read(out, &img)) continue;
        CHECK(st_test_all_finite(&img), "finite");
        int shadowed = 0, lit = 0;
        double worst_lit = 0, worst_shadow = 0;
        for (int j = 0; j < 96; j++)
            for (int i = 0; i < 96; i++) {
                double d[3];
                st_test_ray(&c, i, j, d);
                if (d[1] >= 0 || st_test_ray_box(c.pos, d, BMIN, BMAX) >= 0) continue; // box itself
                double t = -c.pos[1] / d[1], p[3];
                for (int k = 0; k < 3; k++)
                    p[k] = c.pos[k] + t * d[k];
                if (fabs(p[0]) > 3.9 || fabs(p[2]) > 3.9) continue;
                // Footprint of a pixel on the floor, about t * angle per pixel.
                int s = st_test_shadow_state(p, 2.5 * t * 2 * c.tan_half / 96, LP, BMIN, BMAX);
                if (s < 0) continue;
                double l[3] = {LP[0] - p[0], LP[1] - p[1], LP[2] - p[2]};
                double d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
                double e = RHO / M_PI * I * (l[1] / sqrt(d2)) / d2;
                double v = st_image_px(&img, i, j)[0];
                if (s == 1 && with) {
                    shadowed++;
                    if (v > worst_shadow) worst_shadow = v;
                } else {
                    lit++;
                    double rel = fabs(v - e) / e;
                    if (rel > worst_lit) worst_lit = rel;
                }
            }
        if (with) {
            CHECK(shadowed > 100, "shadowed floor pixels: %d", shadowed);
            CHECK(worst_shadow == 0, "shadowed pixels must be black, max %.6g", worst_shadow);
        }
        CHECK(lit > 3000, "lit floor pixels: %d", lit);
        CHECK(worst_lit < 0.01, "lit pixels vs analytic (shadow_map %d): worst rel %.5f", with,
              worst_lit);
        st_image_free(&img);
    }
    return st_test_summary("test_shadow_map");
}
