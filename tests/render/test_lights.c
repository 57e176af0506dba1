// Directional and spot lights on a plane against their closed forms, every
// pixel (docs/physics.md): directional rho/pi E cos e^(-sigma_t path), path
// from the medium's entry plane; spot rho/pi I f cos / d^2 with glTF's
// falloff f written out again here; outside the outer cone exactly 0.
#include "st_test_render.h"

static const double RHO = 0.6;
static const double CAM[3] = {0, 2.5, 3}, TGT[3] = {0, 0, 0}, UP[3] = {0, 1, 0};
enum { W = 96, H = 64 };

static void write_scene(const char *path, const char *light, const char *medium,
                        const char *modules) {
    char json[4096];
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": %d, \"height\": %d},\n"
        " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [%g, %g, %g],"
        " \"fov_y\": 50, \"near\": 0.05, \"far\": 100},\n"
        " \"lights\": [%s],\n"
        " \"geometry\": [{\"quad\": {\"corner\": [-5, 0, -5], \"u\": [0, 0, 10], \"v\": [10, 0, "
        "0]},"
        " \"albedo\": [%g, %g, %g]}],\n%s%s%s"
        " \"modules\": [%s]}\n",
        W, H, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], UP[0], UP[1], UP[2], light, RHO, RHO,
        RHO, medium ? " \"medium\": " : "", medium ? medium : "", medium ? ",\n" : "", modules);
    st_test_write(path, json);
}

typedef double (*expect_fn)(const double p[3], int ch);
static double sigma_t[3]; // the medium's extinction (0: none)

// Worst relative error over plane pixels where the expectation is > 0; the
// count of pixels expected dark that are not exactly 0 goes to *dark_bad.
static double check(const st_image *img, expect_fn f, int *lit, int *dark, int *dark_bad) {
    st_test_cam c = st_test_camera(CAM, TGT, UP, 50, W, H);
    double worst = 0;
    *lit = *dark = *dark_bad = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            if (d[1] >= -1e-3) continue;
            double t = -CAM[1] / d[1], p[3];
            for (int k = 0; k < 3; k++)
                p[k] = CAM[k] + t * d[k];
            if (fabs(p[0]) > 4.9 || fabs(p[2]) > 4.9) continue;
            const float *px = st_image_px(img, i, j);
            double e0 = f(p, 0);
            if (e0 <= 0) {
                (*dark)++;
                *dark_bad += px[0] != 0 || px[1] != 0 || px[2] != 0;
                continue;
            }
            if (e0 < 1e-3 * f((double[]){0.3, 0, -0.2}, 0)) continue; // the cone's rim, where f ~ 0
            (*lit)++;
            // The view ray from p to the camera is attenuated too (t: its length).
            for (int ch = 0; ch < 3; ch++) {
                double e = f(p, ch) * exp(-sigma_t[ch] * t);
                worst = fmax(worst, fabs(px[ch] - e) / e);
            }
        }
    return worst;
}

// ---- directional --------------------------------------------------------------
static const double E[3] = {1.0, 2.0, 3.0};
static double sun_dir[3]; // travel direction, unit
static double entry;      // max over the plane's corners of dot(c, -dir)

static double expect_sun(const double p[3], int ch) {
    double c = -sun_dir[1]; // the plane's normal is +y
    double path = entry - (-(p[0] * sun_dir[0] + p[1] * sun_dir[1] + p[2] * sun_dir[2]));
    return RHO / M_PI * E[ch] * c * exp(-sigma_t[ch] * fmax(path, 0.0));
}

// ---- spot ---------------------------------------------------------------------
static const double SP[3] = {0.3, 1.5, -0.2}, SI[3] = {3.0, 2.0, 1.0}, INNER = 20, OUTER = 35;
static double spot_dir[3];

static double expect_spot(const double p[3], int ch) {
    double l[3] = {SP[0] - p[0], SP[1] - p[1], SP[2] - p[2]};
    double d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2], d = sqrt(d2);
    // KHR_lights_punctual: cd = dot(axis, -l/d), smooth in cos between the cones.
    double cd = -(spot_dir[0] * l[0] + spot_dir[1] * l[1] + spot_dir[2] * l[2]) / d;
    double co = cos(OUTER * M_PI / 180), ci = cos(INNER * M_PI / 180);
    double a = (cd - co) / fmax(0.001, ci - co);
    a = a < 0 ? 0 : a > 1 ? 1 : a;
    return RHO / M_PI * SI[ch] * a * a * (l[1] / d) / d2;
}

static void run(const char *what, const char *scene, const char *out, expect_fn f, int want_dark) {
    CHECK(st_test_render(scene, out, NULL) == 0, "%s: render", what);
    st_image img = {0};
    if (!st_test_read(out, &img)) return;
    int lit, dark, dark_bad;
    double worst = check(&img, f, &lit, &dark, &dark_bad);
    printf("  %-28s worst relative error %.2e over %d lit pixels, %d dark (%d not 0)\n", what,
           worst, lit, dark, dark_bad);
    CHECK(lit > 500, "%s: %d lit pixels", what, lit);
    CHECK(worst < 0.01, "%s: worst relative error %.4f", what, worst);
    CHECK(!want_dark || (dark > 200 && dark_bad == 0), "%s: %d dark pixels, %d of them not 0", what,
          dark, dark_bad);
    CHECK(st_test_all_finite(&img), "%s: finite", what);
    st_image_free(&img);
}

int main(void) {
    char scene[512], out[512], light[512];
    snprintf(scene, sizeof scene, "%s/lights.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/lights.exr", ST_TEST_SCRATCH);

    const double sd[3] = {0.3, -1.0, 0.2};
    double sl = sqrt(sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]);
    for (int k = 0; k < 3; k++)
        sun_dir[k] = sd[k] / sl;
    snprintf(
        light, sizeof light,
        "{\"type\": \"directional\", \"direction\": [%g, %g, %g], \"irradiance\": [%g, %g, %g]}",
        sd[0], sd[1], sd[2], E[0], E[1], E[2]);
    write_scene(scene, light, NULL, "");
    run("directional", scene, out, expect_sun, 0);

    // In a medium: the light enters at the plane touching the scene's bounds
    // (the quad's corners) on its side.
    entry = -INFINITY;
    for (int k = 0; k < 4; k++) {
        double c[3] = {k & 1 ? 5 : -5, 0, k & 2 ? 5 : -5};
        entry = fmax(entry, -(c[0] * sun_dir[0] + c[1] * sun_dir[1] + c[2] * sun_dir[2]));
    }
    sigma_t[0] = 0.05, sigma_t[1] = 0.1, sigma_t[2] = 0.2;
    write_scene(scene, light, "{\"sigma_s\": [0.01, 0.02, 0.05], \"sigma_a\": [0.04, 0.08, 0.15]}",
                "");
    run("directional in a medium", scene, out, expect_sun, 0);
    sigma_t[0] = sigma_t[1] = sigma_t[2] = 0;

    const double ad[3] = {0.2, -1.0, -0.1};
    double al = sqrt(ad[0] * ad[0] + ad[1] * ad[1] + ad[2] * ad[2]);
    for (int k = 0; k < 3; k++)
        spot_dir[k] = ad[k] / al;
    snprintf(light, sizeof light,
             "{\"type\": \"spot\", \"position\": [%g, %g, %g], \"direction\": [%g, %g, %g], "
             "\"intensity\": [%g, %g, %g],"
             " \"inner_angle\": %g, \"outer_angle\": %g}",
             SP[0], SP[1], SP[2], ad[0], ad[1], ad[2], SI[0], SI[1], SI[2], INNER, OUTER);
    write_scene(scene, light, NULL, "");
    run("spot", scene, out, expect_spot, 1);
    // shadow_map handles spots in its cube: no acne, the cone's outside stays 0.
    write_scene(scene, light, NULL,
                "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}}");
    run("spot with shadow_map", scene, out, expect_spot, 1);
    return st_test_summary("test_lights");
}
