// mitchell and sousa with the sun (a directional light) and the scene's
// background as their sky (in-process worlds, 33x33 images, camera at z = 5
// looking down -z, fov_y 40; the god-ray term is the image minus the same
// scene rendered without the module):
// - where the sun lands on the screen: its direction projected with w = 0,
//   u = 1/2 + tan(theta) / (2 tan 20 deg), the limit of a point far along it;
// - fade: exactly 0 behind the camera, on its plane and as w -> 0+ (no NaN),
//   continuous in the angle and 0 from atan(2 tan 20 deg) = 36.05 deg on;
// - radiometry: the sun's source radiance is E / Omega of its disc, the tint
//   is that over the brightest light's, so the shafts scale with E beside a
//   point light; the disc at the sun's pixel in mitchell: exposure (1 + n) x
//   tint, scaled by r_px^2 below one texel; sousa at the sun's pixel: b^3
//   x tint x background;
// - the background: drawn where no geometry is, mitchell's occlusion image
//   shows it, sousa's far mask emits it; a black background stops sousa;
// - the sun in a sweep turning the camera away: shafts fade to exactly 0 and
//   the passes are skipped/culled then.
#include "st_test_support.h"
#include "mitchell/godray_test.h"
#include "st_godray.h"
#include "st_physics.h"

#define RES 33
static const double T20 = 0.36397023426620234; // tan(20 deg)
static const char *MEDIUM = "{\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]}";
static char json[8192];

// The scene: camera at (0, 0, 5) toward -z, `lights`, `geometry`, medium,
// optional background and one module (`module` NULL: none).
static const char *scene_json(const char *lights, const char *geometry, const char *background,
                              const char *module, const char *params) {
    char mod[1024] = "";
    if (module)
        snprintf(mod, sizeof mod, "{\"name\": \"%s\", \"params\": {%s}}", module,
                 params ? params : "");
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 40, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [%s],\n \"geometry\": [%s],\n \"medium\": %s,\n%s%s%s"
             " \"modules\": [%s]}\n",
             RES, RES, lights, geometry, MEDIUM, background ? " \"background\": " : "",
             background ? background : "", background ? ",\n" : "", mod);
    return json;
}

// effect = image with the module - image without it.
static bool render_effect(const char *lights, const char *geometry, const char *background,
                          const char *module, const char *params, st_image *effect,
                          st_image *without) {
    st_scene a, b;
    char with_json[8192];
    snprintf(with_json, sizeof with_json, "%s",
             scene_json(lights, geometry, background, module, params));
    gt_scene(with_json, &a);
    gt_scene(scene_json(lights, geometry, background, NULL, NULL), &b);
    st_world *wa = gt_world(&a), *wb = gt_world(&b);
    st_image ia = {0};
    memset(effect, 0, sizeof *effect);
    memset(without, 0, sizeof *without);
    bool ok = gt_frames(wa, 1, &ia) && gt_frames(wb, 1, without);
    st_world_destroy(wa);
    st_world_destroy(wb);
    st_scene_free(&a);
    st_scene_free(&b);
    if (!ok) return false;
    CHECK(st_test_all_finite(&ia), "%s: finite output", module);
    st_err err = {0};
    st_image_alloc(effect, RES, RES, 3, &err);
    for (int i = 0; i < RES * RES * 3; i++)
        effect->data[i] = ia.data[i] - without->data[i];
    st_image_free(&ia);
    return true;
}

// A sun in the direction of travel d as scene JSON.
static const char *sun_json(char *buf, size_t n, const double d[3], const double E[3],
                            double diameter_deg) {
    snprintf(buf, n,
             "{\"type\": \"directional\", \"direction\": [%.9g, %.9g, %.9g], \"irradiance\": "
             "[%g, %g, %g], \"angular_diameter\": %g}",
             d[0], d[1], d[2], E[0], E[1], E[2], diameter_deg);
    return buf;
}

// ---- screen position and fade ----------------------------------------------------

static const st_camera *camera_of(st_world **w, st_scene *sc) {
    gt_scene(scene_json("", "", NULL, NULL, NULL), sc);
    *w = gt_world(sc);
    return st_world_camera(*w);
}

static void test_screen_position(void) {
    st_scene sc;
    st_world *w;
    const st_camera *c = camera_of(&w, &sc);
    // Toward the sun at 10 deg right of the axis and 5 deg up.
    double th = 10 * ST_PI / 180, ph = 5 * ST_PI / 180;
    float to[3] = {(float)(sin(th) * cos(ph)), (float)sin(ph), (float)(-cos(th) * cos(ph))};
    st_godray_light l = st_godray_project_dir(c->view_proj, RES, RES, to, 0.5);
    double u = 0.5 + 0.5 * (to[0] / -to[2]) / T20, v = 0.5 + 0.5 * (to[1] / -to[2]) / T20;
    printf("sun at (10, 5) deg: uv (%.6f, %.6f), expected (%.6f, %.6f), fade %g, w %.6f\n", l.uv[0],
           l.uv[1], u, v, l.fade, l.w);
    CHECK(fabs(l.uv[0] - u) < 1e-5 && fabs(l.uv[1] - v) < 1e-5, "sun uv (%g, %g) vs (%g, %g)",
          l.uv[0], l.uv[1], u, v);
    CHECK(l.fade == 1 && fabs(l.w - cos(th) * cos(ph)) < 1e-6, "on screen: fade %g, w %g", l.fade,
          l.w);
    // The limit of a point light far along the direction (inside far = 100).
    float p[3] = {50 * to[0], 50 * to[1], 5 + 50 * to[2]};
    st_godray_light q = st_godray_project(c->view_proj, c->near_z, RES, RES, p, 0.5);
    CHECK(fabs(q.uv[0] - l.uv[0]) < 1e-5 && fabs(q.uv[1] - l.uv[1]) < 1e-5,
          "a point 50 m along the direction lands on the sun: (%g, %g) vs (%g, %g)", q.uv[0],
          q.uv[1], l.uv[0], l.uv[1]);

    // Behind the camera, on its plane, and w -> 0+: fade exactly 0, finite uv.
    const float behind[3] = {0, 0, 1}, side[3] = {1, 0, 0}, grazing[3] = {1, 0, -1e-30f},
                grazing2[3] = {1, 0, -1e-7f};
    const float *cases[4] = {behind, side, grazing, grazing2};
    const char *names[4] = {"behind", "on the camera plane", "w = 1e-30", "w = 1e-7"};
    for (int k = 0; k < 4; k++) {
        l = st_godray_project_dir(c->view_proj, RES, RES, cases[k], 0.5);
        CHECK(l.fade == 0 && isfinite(l.uv[0]) && isfinite(l.uv[1]) && isfinite(l.w),
              "sun %s: fade %g uv (%g, %g)", names[k], l.fade, l.uv[0], l.uv[1]);
    }
    // Turning away: continuous, 0 from atan(2 tan 20) on (off-screen margin
    // 0.5 screen heights past u = 1), never NaN.
    double zero_at = atan(2 * T20) * 180 / ST_PI, prev = 1, jump = 0;
    int bad = 0;
    double first_zero = -1;
    for (int s = 0; s <= 1800; s++) {
        double a = s * 0.1 * ST_PI / 180;
        float d[3] = {(float)sin(a), 0, (float)-cos(a)};
        l = st_godray_project_dir(c->view_proj, RES, RES, d, 0.5);
        bad += !isfinite(l.fade) || !isfinite(l.uv[0]);
        jump = fmax(jump, fabs(l.fade - prev));
        prev = l.fade;
        if (l.fade == 0 && first_zero < 0) first_zero = s * 0.1;
        if (l.fade != 0) first_zero = -1;
    }
    printf("sun turning away: fade 0 from %.1f deg (expected %.2f), largest step %.4f per 0.1 "
           "deg\n",
           first_zero, zero_at, jump);
    CHECK(bad == 0, "turning: %d non-finite", bad);
    CHECK(fabs(first_zero - zero_at) <= 0.1, "fade 0 from %g deg, expected %g", first_zero,
          zero_at);
    CHECK(jump < 0.02, "fade continuous: largest step %g", jump);
    st_world_destroy(w);
    st_scene_free(&sc);
}

// ---- radiometry ------------------------------------------------------------------

static double disc_solid_angle(double diameter_deg) {
    return 2 * ST_PI * (1 - cos(0.5 * diameter_deg * ST_PI / 180));
}

static void test_source_radiance(void) {
    st_light_desc sun = {.type = ST_LIGHT_DIRECTIONAL, .intensity = {2, 1, 0.5}},
                  pt = {.type = ST_LIGHT_POINT, .intensity = {100, 100, 100}};
    double L[3], Om = disc_solid_angle(0.53);
    st_godray_source_radiance(&sun, 0.1, L); // angular_diameter 0: the default 0.53 deg
    CHECK_REL(L[0], 2 / Om, 1e-6, 0);
    CHECK_REL(L[2], 0.5 / Om, 1e-6, 0);
    printf("sun E = 2 W/m^2, 0.53 deg: source radiance %.1f W/(m^2 sr) (Omega %.4e sr)\n", L[0],
           Om);
    st_godray_source_radiance(&pt, 0.1, L);
    CHECK_REL(L[1], 100 / (ST_PI * 0.01), 1e-6, 0);
    // Mixed: the brightest source is 1, the other keeps the physical ratio.
    sun.intensity[0] = 0.2f, sun.angular_diameter = (float)(10 * ST_PI / 180);
    st_light_desc both[2] = {pt, sun};
    float t[3];
    st_godray_tint(both, 2, 1, 0.1, t);
    double want = (0.2 / disc_solid_angle(10)) / (100 / (ST_PI * 0.01));
    CHECK_REL(t[0], want, 1e-5, 0);
    st_godray_tint(both, 2, 0, 0.1, t);
    CHECK(t[0] == 1 && t[1] == 1, "the point light is the brightest: tint %g", t[0]);
}

static const double AHEAD[3] = {0, 0, 1}; // travelling toward the camera: the sun straight ahead

// mitchell: the sun on the view axis lands on pixel (16, 16)'s centre; every
// tap there reads the disc. n 10, decay 0.5, weight 2, exposure 0.05: effect
// = 0.05 (1 + 2 (1 - 0.5^10) / 0.5) x disc radiance.
static void test_mitchell_sun_pixel(void) {
    const char *params = "\"n\": 10, \"density\": 1.4, \"decay\": 0.5, \"weight\": 2, "
                         "\"exposure\": 0.05, \"resolution\": 1";
    const double factor = 0.05 * (1 + 2 * (1 - pow(0.5, 10)) / 0.5);
    char sun[256];
    st_image e, base;
    // A 10 degree disc: 3.95 px radius, drawn at the tint (1, 0.5, 0.25).
    if (render_effect(sun_json(sun, sizeof sun, AHEAD, (double[]){4, 2, 1}, 10), "", NULL,
                      "mitchell", params, &e, &base)) {
        const float *p = st_image_px(&e, 16, 16);
        printf("mitchell sun pixel (10 deg disc): (%.6f, %.6f, %.6f), expected %.6f x (1, 0.5, "
               "0.25)\n",
               p[0], p[1], p[2], factor);
        CHECK_REL(p[0], factor, 1e-4, 1e-6);
        CHECK_REL(p[1], factor * 0.5, 1e-4, 1e-6);
        CHECK_REL(p[2], factor * 0.25, 1e-4, 1e-6);
        st_image_free(&e);
        st_image_free(&base);
    }
    // The default 0.53 degree disc: r_px = sin(0.265 deg) / tan(20 deg) x 16.5
    // = 0.21 texels, drawn one texel wide at tint x r_px^2.
    if (render_effect(sun_json(sun, sizeof sun, AHEAD, (double[]){1, 1, 1}, 0.53), "", NULL,
                      "mitchell", params, &e, &base)) {
        double r_px = sin(0.265 * ST_PI / 180) / T20 * RES / 2;
        const float *p = st_image_px(&e, 16, 16);
        printf("mitchell sun pixel (0.53 deg disc, r = %.4f px): %.6g, expected %.6g\n", r_px, p[0],
               factor * r_px * r_px);
        CHECK_REL(p[0], factor * r_px * r_px, 1e-3, 1e-7);
        st_image_free(&e);
        st_image_free(&base);
    }
}

// Beside a brighter point light (behind the camera, so it casts no shafts of
// its own), the sun's shafts scale with its irradiance: 2 E gives twice the
// effect, everywhere, for both techniques (mitchell without a sky, which
// would add a part that does not scale).
static void test_energy_scaling(void) {
    const char *point = "{\"type\": \"point\", \"position\": [0, 0, 8], \"intensity\": [400, 400, "
                        "400]}";
    const char *geo = "{\"box\": {\"min\": [-0.6, -0.05, -2], \"max\": [0.6, 0.05, -1.9]}}";
    const char *modules[2] = {"mitchell", "sousa"};
    const char *params[2] = {"\"n\": 24, \"density\": 1, \"exposure\": 0.05, \"resolution\": 0.5",
                             "\"brightness\": 0.5"};
    for (int m = 0; m < 2; m++) {
        double sums[2] = {0, 0}, worst = 0;
        st_image e[2], base[2];
        bool ok = true;
        for (int k = 0; k < 2 && ok; k++) {
            char sun[256], lights[512];
            double E = 30.0 * (k + 1); // source radiance 1255 and 2509 < 400 / (pi 0.01) = 12732
            snprintf(lights, sizeof lights, "%s, %s", point,
                     sun_json(sun, sizeof sun, AHEAD, (double[]){E, E, E}, 10));
            // mitchell's sky does not scale with the sun: none; sousa's needs one (x 0.5).
            ok = render_effect(lights, geo, m ? "[0.5, 0.5, 0.5]" : NULL, modules[m], params[m],
                               &e[k], &base[k]);
            for (int i = 0; ok && i < RES * RES * 3; i++)
                sums[k] += e[k].data[i];
        }
        if (!ok) continue;
        for (int i = 0; i < RES * RES * 3; i++)
            worst = fmax(worst, fabs(e[1].data[i] - 2 * e[0].data[i]));
        double tint = (30 / disc_solid_angle(10)) / (400 / (ST_PI * 0.01));
        printf("%s: effect energy %.6g at E = 30, %.6g at E = 60 (ratio %.5f); sun tint %.5f; max "
               "|e(2E) - 2 e(E)| %.2g\n",
               modules[m], sums[0], sums[1], sums[1] / sums[0], tint, worst);
        CHECK(sums[0] > 0.01, "%s: shafts visible: %g", modules[m], sums[0]);
        CHECK(worst < 1e-5 * fmax(1, sums[1]), "%s: effect scales with E: %g", modules[m], worst);
        for (int k = 0; k < 2; k++)
            st_image_free(&e[k]), st_image_free(&base[k]);
    }
}

// ---- the background as the sky ------------------------------------------------------

// The regular pass draws the background where no geometry is, seen through
// the medium: B e^(-sigma_t far / cos), cos the ray's angle to the view axis
// (docs/physics.md; far 100, sigma_t 0.11: about 1.6e-5 B); mitchell's
// occlusion image holds it (n 4, density 1000, exposure 0.2: the effect of a
// texel is (1 + 4) 0.2 = 1 times the image); sousa's far mask emits it:
// at the sun's pixel only the pixel's own tap is taken in each pass, so the
// effect there is b^3 x tint x background.
static void test_background(void) {
    const char *geo = "{\"quad\": {\"corner\": [-0.5, -1.5, 0], \"u\": [1, 0, 0], \"v\": [0, 1, "
                      "0]}, \"albedo\": [0.5, 0.5, 0.5]}";
    const double B[3] = {0.2, 0.3, 0.6};
    char sun[256];
    sun_json(sun, sizeof sun, AHEAD, (double[]){1, 1, 1}, 0.53);
    st_image e, base;
    if (render_effect(sun, geo, "[0.2, 0.3, 0.6]", "mitchell",
                      "\"n\": 4, \"density\": 1000, \"weight\": 1, \"exposure\": 0.2, "
                      "\"resolution\": 1",
                      &e, &base)) {
        // Row 2 from the top sees sky; the quad covers rows 20..30 of columns 12..20.
        double worst_bg = 0, worst_sky = 0, worst_quad = 0;
        for (int i = 0; i < RES; i++)
            for (int c = 0; c < 3; c++) {
                // Pixel (i, 2): its ray's tangents along x and y.
                double x = (2.0 * (i + 0.5) / RES - 1.0) * T20, y = (1.0 - 2.0 * 2.5 / RES) * T20;
                double want = B[c] * exp(-0.11 * 100.0 * sqrt(1.0 + x * x + y * y));
                worst_bg = fmax(worst_bg, fabs(st_image_px(&base, i, 2)[c] - want) / want);
                worst_sky = fmax(worst_sky, fabs(st_image_px(&e, i, 2)[c] - B[c]));
            }
        for (int c = 0; c < 3; c++)
            worst_quad = fmax(worst_quad, fabs(st_image_px(&e, 16, 26)[c]));
        printf("background: regular pass max |L - B T| / B T %.2g; mitchell occlusion sky max "
               "|effect - B| "
               "%.2g, occluder %.2g\n",
               worst_bg, worst_sky, worst_quad);
        CHECK(worst_bg < 1e-3, "the background where no geometry is, dimmed: rel. %g", worst_bg);
        CHECK(worst_sky < 1e-5, "mitchell: the sky is the background: %g", worst_sky);
        CHECK(worst_quad < 1e-6, "mitchell: the quad occludes it: %g", worst_quad);
        st_image_free(&e);
        st_image_free(&base);
    }
    const double b = 0.3;
    for (int k = 0; k < 2; k++) {
        const char *bg = k ? "[0.2, 0.3, 0.6]" : NULL;
        if (!render_effect(sun, geo, bg, "sousa", "\"brightness\": 0.3", &e, &base)) continue;
        const float *p = st_image_px(&e, 16, 16);
        for (int c = 0; c < 3; c++)
            CHECK_REL(p[c], b * b * b * (k ? B[c] : 1), 1e-4, 1e-7);
        printf("sousa sun pixel %s: (%.6f, %.6f, %.6f), expected b^3 = %.6f x %s\n",
               k ? "with background" : "without", p[0], p[1], p[2], b * b * b,
               k ? "(0.2, 0.3, 0.6)" : "1");
        st_image_free(&e);
        st_image_free(&base);
    }
    // A black sky emits nothing: sousa's passes do not run at all.
    st_scene sc;
    gt_scene(scene_json(sun, geo, "[0, 0, 0]", "sousa", ""), &sc);
    st_world *w = gt_world(&sc);
    st_image img = {0};
    if (gt_frames(w, 1, &img)) {
        unsigned runs, skipped, culled;
        gt_stats(w, "sousa", "blur3", &runs, &skipped, &culled);
        CHECK(runs == 0 && skipped == 1, "black background: blur3 runs %u skipped %u", runs,
              skipped);
        gt_stats(w, "sousa", "mask", &runs, &skipped, &culled);
        CHECK(runs == 0 && culled == 1, "black background: mask runs %u culled %u", runs, culled);
    }
    st_image_free(&img);
    st_world_destroy(w);
    st_scene_free(&sc);
}

// ---- sweeps: turning away from the sun ----------------------------------------------

static void sun_pose_turn(double t, double pos[3], double tgt[3]) {
    double th = t * ST_PI;
    pos[0] = 0, pos[1] = 0, pos[2] = 5;
    tgt[0] = sin(th), tgt[1] = 0, tgt[2] = 5 - cos(th);
}

static void test_sweep(void) {
    char sun[256], with[8192], without[8192];
    sun_json(sun, sizeof sun, AHEAD, (double[]){1, 1, 1}, 2);
    const char *geo = "{\"box\": {\"min\": [-0.5, -0.1, -1], \"max\": [0.5, 0.1, -0.9]}}";
    const char *mods[2] = {"mitchell", "sousa"},
               *params[2] = {"\"n\": 24, \"density\": 1, \"exposure\": "
                             "0.05, \"resolution\": 0.5",
                             ""};
    const char *last[2] = {"blur", "blur3"}, *first[2] = {"occlusion", "blur1"};
    for (int m = 0; m < 2; m++) {
        snprintf(with, sizeof with, "%s",
                 scene_json(sun, geo, "[0.2, 0.3, 0.6]", mods[m], params[m]));
        snprintf(without, sizeof without, "%s",
                 scene_json(sun, geo, "[0.2, 0.3, 0.6]", NULL, NULL));
        char what[64];
        snprintf(what, sizeof what, "%s: turning away from the sun", mods[m]);
        gt_check_sweep(what, mods[m], last[m], first[m], with, without, 24, sun_pose_turn);
    }
}

int main(void) {
    st_context *ctx = st_test_context();
    test_screen_position();
    test_source_radiance();
    test_mitchell_sun_pixel();
    test_energy_scaling();
    test_background();
    test_sweep();
    st_context_destroy(ctx);
    return st_test_summary("test_godray_sun");
}
