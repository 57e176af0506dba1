// Direct light on a plane against rho/pi * I * cos / d^2, every pixel; in a
// medium times e^(-sigma_t d) on the light's path (docs/physics.md).
#include "st_test_render.h"

static const double I[3] = {2.0, 1.0, 0.5}, LP[3] = {0.3, 1.0, -0.2}, RHO = 0.6;

static void write_scene(const char *path, const double cam[3], const double tgt[3],
                        const double up[3], int w, int h, const char *modules, const char *medium) {
    char json[2048];
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": %d, \"height\": %d},\n"
        " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [%g, %g, %g],"
        " \"fov_y\": 50, \"near\": 0.05, \"far\": 100},\n"
        " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, %g, "
        "%g]}],\n"
        " \"geometry\": [{\"quad\": {\"corner\": [-5, 0, -5], \"u\": [0, 0, 10], \"v\": [10, 0, "
        "0]},"
        " \"albedo\": [%g, %g, %g]}],\n%s%s%s"
        " \"modules\": [%s]}\n",
        w, h, cam[0], cam[1], cam[2], tgt[0], tgt[1], tgt[2], up[0], up[1], up[2], LP[0], LP[1],
        LP[2], I[0], I[1], I[2], RHO, RHO, RHO, medium ? " \"medium\": " : "", medium ? medium : "",
        medium ? ",\n" : "", modules);
    st_test_write(path, json);
}

// Checks every pixel that sees the plane; returns the worst relative error.
// sigma_t: the medium's extinction on the light's path and on the view ray
// from the plane to the camera (NULL: none).
static double check_plane(const st_image *img, const st_test_cam *c, const double *sigma_t,
                          int *count) {
    double worst = 0;
    *count = 0;
    for (int j = 0; j < img->height; j++)
        for (int i = 0; i < img->width; i++) {
            double d[3];
            st_test_ray(c, i, j, d);
            if (d[1] >= -1e-3) continue;
            double t = -c->pos[1] / d[1], p[3];
            for (int k = 0; k < 3; k++)
                p[k] = c->pos[k] + t * d[k];
            if (fabs(p[0]) > 4.9 || fabs(p[2]) > 4.9) continue;
            double l[3] = {LP[0] - p[0], LP[1] - p[1], LP[2] - p[2]};
            double d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
            double cosv = l[1] / sqrt(d2);
            const float *px = st_image_px(img, i, j);
            for (int ch = 0; ch < 3; ch++) {
                double e = RHO / M_PI * I[ch] * cosv / d2 *
                           (sigma_t ? exp(-sigma_t[ch] * (sqrt(d2) + t)) : 1.0);
                double rel = fabs(px[ch] - e) / e;
                if (rel > worst) worst = rel;
            }
            (*count)++;
        }
    return worst;
}

int main(void) {
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/plane.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/plane.exr", ST_TEST_SCRATCH);

    // 1. Straight under the light: odd size, the centre pixel looks straight down.
    const double cam1[3] = {LP[0], 3, LP[2]}, tgt1[3] = {LP[0], 0, LP[2]}, up1[3] = {0, 0, -1};
    write_scene(scene, cam1, tgt1, up1, 33, 33, "", NULL);
    CHECK(st_test_render(scene, out, NULL) == 0, "render plane (top view)");
    st_image img = {0};
    if (st_test_read(out, &img)) {
        const float *px = st_image_px(&img, 16, 16);
        for (int ch = 0; ch < 3; ch++)
            CHECK_REL(px[ch], RHO / M_PI * I[ch] / (LP[1] * LP[1]), 0.01, 0);
        CHECK(st_test_all_finite(&img), "finite");
        st_image_free(&img);
    }

    // 2. Oblique view: every plane pixel obeys the cosine and inverse-square laws.
    const double cam2[3] = {0, 2.5, 3}, tgt2[3] = {0, 0, 0}, up2[3] = {0, 1, 0};
    write_scene(scene, cam2, tgt2, up2, 96, 64, "", NULL);
    CHECK(st_test_render(scene, out, NULL) == 0, "render plane (oblique)");
    st_test_cam c = st_test_camera(cam2, tgt2, up2, 50, 96, 64);
    if (st_test_read(out, &img)) {
        int n;
        double worst = check_plane(&img, &c, NULL, &n);
        CHECK(n > 3000, "pixels on the plane: %d", n);
        CHECK(worst < 0.01, "worst relative error %.5f over %d pixels", worst, n);
        CHECK(st_test_all_finite(&img), "finite");
        st_image_free(&img);
    }

    // 3. Same with shadow_map: a lit plane shows no acne (every pixel within 1%).
    write_scene(scene, cam2, tgt2, up2, 96, 64,
                "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}}", NULL);
    CHECK(st_test_render(scene, out, NULL) == 0, "render plane with shadow_map");
    if (st_test_read(out, &img)) {
        int n;
        double worst = check_plane(&img, &c, NULL, &n);
        CHECK(worst < 0.01, "shadow acne: worst relative error %.5f over %d pixels", worst, n);
        st_image_free(&img);
    }
    // And with PCF on.
    write_scene(scene, cam2, tgt2, up2, 96, 64,
                "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512, \"pcf\": true}}",
                NULL);
    CHECK(st_test_render(scene, out, NULL) == 0, "render plane with PCF");
    if (st_test_read(out, &img)) {
        int n;
        double worst = check_plane(&img, &c, NULL, &n);
        CHECK(worst < 0.01, "PCF acne: worst relative error %.5f over %d pixels", worst, n);
        st_image_free(&img);
    }
    // 4. In a medium, light reaching the plane is attenuated by e^(-sigma_t d)
    // per channel, and the view ray by e^(-sigma_t t) (the regular pass owns
    // it). No volumetric module: no in-scatter (toth adds that; tests/toth).
    const double sigma_t[3] = {0.12, 0.3, 0.6};
    write_scene(scene, cam2, tgt2, up2, 96, 64,
                "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}}",
                "{\"sigma_s\": [0.02, 0.1, 0.2], \"sigma_a\": [0.1, 0.2, 0.4]}");
    CHECK(st_test_render(scene, out, NULL) == 0, "render plane in a medium");
    if (st_test_read(out, &img)) {
        int n;
        double worst = check_plane(&img, &c, sigma_t, &n);
        double plain = check_plane(&img, &c, NULL, &n);
        CHECK(worst < 0.01, "medium: worst relative error %.5f over %d pixels", worst, n);
        CHECK(plain > 0.2, "medium: the attenuation is visible (%.3f off the unattenuated law)",
              plain);
        st_image_free(&img);
    }
    return st_test_summary("test_direct_light");
}
