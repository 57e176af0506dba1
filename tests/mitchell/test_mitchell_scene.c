// The mitchell plugin in scenes (in-process worlds, 33x33 images; the
// god-ray term is the image minus the same scene rendered without medium):
// - occlusion image content: emitters at their emission radiance, occluders
//   and back sides black, the light's disc in its tint, the sky colour; a
//   closed smooth emitter the same single- or double-sided;
// - the light's own pixel: exposure tint (1 + weight sum decay^i);
// - several lights add up;
// - off screen and behind the camera: the shafts fade continuously to 0,
//   then the blur pass is skipped and the occlusion pass culled;
// - no medium / sigma_s = 0 / exposure 0: nothing runs (also in --stats=json);
// - a static view draws the occlusion image once;
// - stress: light at a pixel centre, at the camera, behind it, on a surface,
//   inside the near range; every parameter at its range limits: all finite.
#include "st_test_support.h"
#include "mitchell/godray_test.h"
#include "st_godray.h"
#include <cjson/cJSON.h>

#define RES 33
static const double CAM[3] = {0, 0, 5};

static char json[8192];

// A scene around the camera at CAM looking down -z (unless `camera` is
// given), with `geometry`, `lights`, an optional medium and mitchell params.
static const char *scene_json(const char *lights, const char *geometry, const char *medium,
                              const char *params, const char *camera) {
    char cam[512];
    snprintf(
        cam, sizeof cam,
        "{\"position\": [%g, %g, %g], \"target\": [%g, %g, 0], \"up\": [0, 1, 0], \"fov_y\": 40, "
        "\"near\": 0.05, \"far\": 100}",
        CAM[0], CAM[1], CAM[2], CAM[0], CAM[1]);
    return gt_scene_json(json, sizeof json, RES, camera ? camera : cam, lights, geometry, medium,
                         "mitchell", params);
}

static const char *MEDIUM = "{\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]}";

// The scene with and without the module (effect = the difference).
static bool render_effect(const char *lights, const char *geometry, const char *params,
                          const char *camera, gt_pair *r) {
    char with[sizeof json];
    snprintf(with, sizeof with, "%s", scene_json(lights, geometry, MEDIUM, params, camera));
    bool ok = gt_render_pair(with, scene_json(lights, geometry, MEDIUM, NULL, camera), r);
    CHECK(ok && st_test_all_finite(&r->with), "finite output");
    return ok;
}

// ---- occlusion image content ------------------------------------------------

// Ray through image point (x, y) in pixels (y down, 0 at the top edge).
static void ray_at(double x, double y, double d[3]) {
    double t = tan(20 * M_PI / 180);
    d[0] = (2 * x / RES - 1) * t, d[1] = (1 - 2 * y / RES) * t, d[2] = -1;
    st_v_norm(d);
}

static double ray_quad_z(const double d[3], double z, double x0, double x1, double y0, double y1) {
    double t = (z - CAM[2]) / d[2];
    if (t <= 0) return -1;
    double x = CAM[0] + t * d[0], y = CAM[1] + t * d[1];
    return x >= x0 && x <= x1 && y >= y0 && y <= y1 ? t : -1;
}

enum { C_SKY, C_EMITTER, C_OCCLUDER, C_BACK, C_LIGHT };
static const double LIGHT_A[3] = {0.4, 0.5, 0}, RADIUS_A = 0.4;
static const double BOX_MIN[3] = {-1.0, 0.2, -0.5}, BOX_MAX[3] = {-0.3, 0.9, -0.3};

static int classify(double x, double y) {
    double d[3];
    ray_at(x, y, d);
    double best = 1e30;
    int cls = C_SKY;
    double t;
    if ((t = ray_quad_z(d, -1, -1.2, 1.2, -1.2, 1.2)) > 0 && t < best) best = t, cls = C_EMITTER;
    if ((t = ray_quad_z(d, 0.5, 0.5, 1.3, -1.5, -0.5)) > 0 && t < best) best = t, cls = C_BACK;
    if ((t = st_test_ray_box(CAM, d, BOX_MIN, BOX_MAX)) > 0 && t < best) best = t, cls = C_OCCLUDER;
    // The light: a screen-facing disc of radius r P11 / w at the depth of
    // the sphere's front, occluded only by what is nearer.
    double w = CAM[2] - LIGHT_A[2], P11 = 1 / tan(20 * M_PI / 180);
    double cx = (LIGHT_A[0] * P11 / w + 1) * RES / 2, cy = (1 - LIGHT_A[1] * P11 / w) * RES / 2;
    double dist = sqrt(pow(LIGHT_A[0], 2) + pow(LIGHT_A[1], 2) + w * w);
    double w_front = w * (dist - RADIUS_A) / dist, w_scene = best < 1e30 ? -best * d[2] : 1e30;
    if (hypot(x - cx, y - cy) < RADIUS_A * P11 / w * RES / 2 && w_front < w_scene) cls = C_LIGHT;
    return cls;
}

static void test_occlusion_content(void) {
    const char *geo = "{\"quad\": {\"corner\": [-1.2, -1.2, -1], \"u\": [2.4, 0, 0], \"v\": [0, "
                      "2.4, 0]}, \"emission\": [0.5, 1, 2]},"
                      "{\"quad\": {\"corner\": [0.5, -1.5, 0.5], \"u\": [0, 1, 0], \"v\": [0.8, 0, "
                      "0]}, \"emission\": [5, 5, 5]},"
                      "{\"box\": {\"min\": [-1.0, 0.2, -0.5], \"max\": [-0.3, 0.9, -0.3]}, "
                      "\"albedo\": [0.5, 0.5, 0.5]}";
    char lights[256];
    snprintf(lights, sizeof lights,
             "{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [2, 1, 0.5]}",
             LIGHT_A[0], LIGHT_A[1], LIGHT_A[2]);
    // density 1000 keeps all 5 taps inside the pixel's own texel, so the
    // effect is exposure (1 + n weight) times the occlusion image = the image.
    char params[256];
    snprintf(params, sizeof params,
             "\"n\": 4, \"density\": 1000, \"decay\": 1, \"weight\": 1, \"exposure\": 0.2, "
             "\"resolution\": 1, "
             "\"sky\": 1, \"light_radius\": %g",
             RADIUS_A);
    gt_pair r;
    if (!render_effect(lights, geo, params, NULL, &r)) return;
    const double expect[5][3] = {
        {0.2, 0.3, 0.6}, {0.5, 1, 2}, {0, 0, 0}, {0, 0, 0}, {1, 0.5, 0.25}};
    int count[5] = {0};
    double worst[5] = {0};
    for (int j = 0; j < RES; j++)
        for (int i = 0; i < RES; i++) {
            int c = classify(i + 0.5, j + 0.5);
            // The taps drift up to 0.03 px toward the light, so the bilinear
            // neighbours (1 and 1.41 px away) must be of the same class too.
            bool robust = true;
            for (int k = 0; k < 24 && robust; k++) {
                double rad = 0.5 * (1 + k / 8);
                robust = classify(i + 0.5 + rad * cos(k * M_PI / 4),
                                  j + 0.5 + rad * sin(k * M_PI / 4)) == c;
            }
            if (!robust) continue;
            count[c]++;
            const float *e = st_image_px(&r.effect, i, j);
            for (int ch = 0; ch < 3; ch++)
                worst[c] = fmax(worst[c], fabs(e[ch] - expect[c][ch]));
        }
    const char *names[5] = {"sky", "emitter front", "occluder", "emitter back", "light disc"};
    for (int c = 0; c < 5; c++) {
        printf("occlusion content: %-14s %4d px, max |effect - expected| = %.3g\n", names[c],
               count[c], worst[c]);
        CHECK(count[c] >= 4, "%s: %d robust pixels", names[c], count[c]);
        CHECK(worst[c] < 1e-4, "%s: max error %g", names[c], worst[c]);
    }
    gt_pair_free(&r);
}

// A closed smooth emitter (a coarse sphere: near its silhouette the
// interpolated normal turns away from the camera, which sees the facets'
// front) is the same single- or double-sided in the occlusion image: the
// facet decides the side (common/facet.glsl), as in the regular pass.
static void test_occlusion_smooth(void) {
    const char *light =
        "{\"type\": \"point\", \"position\": [1.5, 1.5, 0], \"intensity\": [1, 1, 1]}";
    const char *params = "\"n\": 4, \"density\": 1000, \"decay\": 1, \"weight\": 1, "
                         "\"exposure\": 0.2, \"resolution\": 1, \"light_radius\": 0.05";
    const char *fmt = "{\"sphere\": {\"center\": [0, 0, 2.5], \"radius\": 0.8, \"rings\": 4, "
                      "\"segments\": 6}, \"emission\": [1, 0.5, 0.25], \"double_sided\": %s}";
    char geo[2][256];
    gt_pair r[2];
    bool ok = true;
    for (int d = 0; d < 2; d++) {
        snprintf(geo[d], sizeof geo[d], fmt, d ? "true" : "false");
        ok &= render_effect(light, geo[d], params, NULL, &r[d]);
    }
    if (!ok) return;
    int emitting = 0, differ = 0;
    double worst = 0;
    for (int j = 0; j < RES; j++)
        for (int i = 0; i < RES; i++) {
            const float *a = st_image_px(&r[0].effect, i, j), *b = st_image_px(&r[1].effect, i, j);
            emitting += fabs(b[0] - 1) < 1e-3 && fabs(b[1] - 0.5) < 1e-3;
            double e = fmax(fabs(a[0] - b[0]), fmax(fabs(a[1] - b[1]), fabs(a[2] - b[2])));
            worst = fmax(worst, e), differ += e >= 1e-5;
        }
    printf("smooth emitter: %d emitting pixels; single- and double-sided differ in %d, by at "
           "most %.3g\n",
           emitting, differ, worst);
    CHECK(emitting > 400, "smooth emitter: %d emitting pixels", emitting);
    CHECK(worst < 1e-5, "smooth emitter: single- and double-sided differ by %g", worst);
    gt_pair_free(&r[0]);
    gt_pair_free(&r[1]);
}

// ---- the light's own pixel ---------------------------------------------------

static void test_light_pixel(void) {
    // Light on the view axis: uv (0.5, 0.5) is the centre of pixel (16, 16),
    // the step there is 0, every tap reads the sphere's tint.
    gt_pair r;
    const char *light =
        "{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [3, 1.5, 0.3]}";
    const char *params =
        "\"n\": 10, \"density\": 1.4, \"decay\": 0.5, \"weight\": 2, \"exposure\": 0.05, "
        "\"resolution\": 1, \"light_radius\": 0.3";
    if (!render_effect(light, "", params, NULL, &r)) return;
    const float *e = st_image_px(&r.effect, 16, 16);
    double factor = 0.05 * (1 + 2 * (1 - pow(0.5, 10)) / 0.5);
    const double tint[3] = {1, 0.5, 0.1};
    for (int c = 0; c < 3; c++)
        CHECK_REL(e[c], factor * tint[c], 1e-4, 1e-6);
    printf("light pixel: effect (%.6f, %.6f, %.6f), expected %.6f x tint (1, 0.5, 0.1)\n", e[0],
           e[1], e[2], factor);
    // Symmetry about the light (the scene is symmetric up to the sphere's tessellation).
    double asym = 0, peak = 0;
    for (int j = 0; j < RES; j++)
        for (int i = 0; i < RES; i++) {
            double a = st_image_px(&r.effect, i, j)[0],
                   b = st_image_px(&r.effect, RES - 1 - i, RES - 1 - j)[0];
            asym = fmax(asym, fabs(a - b));
            peak = fmax(peak, a);
        }
    printf("light pixel: point-symmetry error %.3g of peak %.3g\n", asym, peak);
    CHECK(asym < 0.05 * peak, "shafts symmetric about the light: %g of %g", asym, peak);
    gt_pair_free(&r);
}

// ---- several lights add up -----------------------------------------------------

static void test_additive(void) {
    const char *geo = "{\"quad\": {\"corner\": [-3, -3, -2], \"u\": [6, 0, 0], \"v\": [0, 6, 0]}, "
                      "\"albedo\": [0.5, 0.5, 0.5]},"
                      "{\"box\": {\"min\": [-0.2, -0.2, -0.5], \"max\": [0.2, 0.2, -0.4]}}";
    const char *l1 =
        "{\"type\": \"point\", \"position\": [-0.6, 0.3, -1], \"intensity\": [1, 1, 1]}";
    const char *l2 =
        "{\"type\": \"point\", \"position\": [0.5, -0.4, -1], \"intensity\": [1, 0.5, 0.5]}";
    char both[512];
    snprintf(both, sizeof both, "%s, %s", l1, l2);
    const char *params = "\"n\": 32, \"density\": 1, \"exposure\": 0.05, \"light_radius\": 0.15, "
                         "\"resolution\": 0.5";
    gt_pair a, b, ab;
    if (!render_effect(l1, geo, params, NULL, &a) || !render_effect(l2, geo, params, NULL, &b) ||
        !render_effect(both, geo, params, NULL, &ab))
        return;
    double worst = 0, peak = 0;
    for (int i = 0; i < RES * RES * 3; i++) {
        worst = fmax(worst, fabs(ab.effect.data[i] - a.effect.data[i] - b.effect.data[i]));
        peak = fmax(peak, ab.effect.data[i]);
    }
    printf("two lights: max |effect(1+2) - effect(1) - effect(2)| = %.3g (peak %.3g)\n", worst,
           peak);
    CHECK(peak > 0.05, "shafts visible: peak %g", peak);
    CHECK(worst < 1e-5 * fmax(1, peak), "lights add up: %g", worst);
    gt_pair_free(&a);
    gt_pair_free(&b);
    gt_pair_free(&ab);
}

// ---- fading off screen and behind the camera --------------------------------------

static void check_sweep(const char *what, int steps, void (*pose)(double, double[3], double[3])) {
    const char *light = "{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [1, 1, 1]}";
    const char *params =
        "\"n\": 24, \"density\": 1, \"exposure\": 0.05, \"sky\": 1, \"resolution\": 0.5";
    const char *geo = "{\"box\": {\"min\": [-0.5, -0.1, -1], \"max\": [0.5, 0.1, -0.9]}}";
    char with[8192];
    snprintf(with, sizeof with, "%s", scene_json(light, geo, MEDIUM, params, NULL));
    gt_check_sweep(what, "mitchell", "blur", "occlusion", with,
                   scene_json(light, geo, MEDIUM, NULL, NULL), steps, pose);
}

static void test_fade(void) {
    check_sweep("slide off screen", 30, godray_pose_slide);
    check_sweep("turn around", 30, godray_pose_turn);
    check_sweep("walk past the light", 30, godray_pose_walk);
    // The fade function itself at the stress positions.
    st_scene sc;
    const char *light = "{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [1, 1, 1]}";
    gt_scene(scene_json(light, "", MEDIUM, "", NULL), &sc);
    st_world *w = gt_world(&sc);
    const st_camera *c = st_world_camera(w);
    const float at_cam[3] = {0, 0, 5}, behind[3] = {0, 0, 6}, ahead[3] = {0, 0, 0},
                near_[3] = {0, 0, 4.925f};
    st_godray_light l = st_godray_project(c->view_proj, c->near_z, RES, RES, at_cam, 0.5);
    CHECK(l.fade == 0 && isfinite(l.uv[0]), "light at the camera: fade %g", l.fade);
    l = st_godray_project(c->view_proj, c->near_z, RES, RES, behind, 0.5);
    CHECK(l.fade == 0, "light behind the camera: fade %g", l.fade);
    l = st_godray_project(c->view_proj, c->near_z, RES, RES, ahead, 0.5);
    CHECK(l.fade == 1 && fabsf(l.uv[0] - 0.5f) < 1e-6f && fabsf(l.uv[1] - 0.5f) < 1e-6f,
          "light ahead: fade %g uv (%g, %g)", l.fade, l.uv[0], l.uv[1]);
    l = st_godray_project(c->view_proj, c->near_z, RES, RES, near_, 0.5); // w = 1.5 near: half way
    CHECK(fabs(l.fade - 0.5) < 1e-3, "light at 1.5 near: fade %g (0.5)", l.fade);
    st_world_destroy(w);
    st_scene_free(&sc);
}

// ---- nothing runs that the scene does not need ------------------------------------

static void expect_idle(const char *what, const char *lights, const char *medium,
                        const char *params, const char *camera) {
    st_scene sc, base;
    gt_scene(
        scene_json(
            lights,
            "{\"box\": {\"min\": [-1, -1, -2], \"max\": [1, 1, -1.5]}, \"emission\": [1, 1, 1]}",
            medium, params, camera),
        &sc);
    gt_scene(
        scene_json(
            lights,
            "{\"box\": {\"min\": [-1, -1, -2], \"max\": [1, 1, -1.5]}, \"emission\": [1, 1, 1]}",
            medium, NULL, camera),
        &base);
    st_world *w = gt_world(&sc), *wb = gt_world(&base);
    st_image a = {0}, b = {0};
    if (gt_frames(w, 3, &a) && gt_frames(wb, 1, &b)) {
        unsigned runs, skipped, culled;
        int n = gt_stats(w, "mitchell", "blur", &runs, &skipped, &culled);
        CHECK(n == sc.num_lights && runs == 0 && skipped == 3u * n, "%s: blur runs %u skipped %u",
              what, runs, skipped);
        n = gt_stats(w, "mitchell", "occlusion", &runs, &skipped, &culled);
        CHECK(runs == 0 && culled == 3u * n, "%s: occlusion runs %u culled %u", what, runs, culled);
        CHECK(gt_image_max_diff(&a, &b) == 0, "%s: image unchanged", what);
        printf("idle (%s): blur skipped, occlusion culled, image identical\n", what);
    }
    st_image_free(&a);
    st_image_free(&b);
    st_world_destroy(w);
    st_world_destroy(wb);
    st_scene_free(&sc);
    st_scene_free(&base);
}

static void test_idle(void) {
    const char *light = "{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [1, 1, 1]}";
    expect_idle("no medium", light, NULL, "", NULL);
    expect_idle("sigma_s = 0", light, "{\"sigma_s\": [0, 0, 0], \"sigma_a\": [0.1, 0.1, 0.1]}", "",
                NULL);
    expect_idle("exposure 0", light, MEDIUM, "\"exposure\": 0", NULL);
    expect_idle("light behind the camera",
                "{\"type\": \"point\", \"position\": [0, 0, 7], \"intensity\": [1, 1, 1]}", MEDIUM,
                "", NULL);
    expect_idle("black light",
                "{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [0, 0, 0]}", MEDIUM,
                "", NULL);

    // Static view with a medium: the occlusion image is drawn once, the blur
    // composes every frame.
    st_scene sc;
    gt_scene(scene_json(light, "", MEDIUM, "", NULL), &sc);
    st_world *w = gt_world(&sc);
    st_image img = {0};
    if (gt_frames(w, 3, &img)) {
        unsigned runs, skipped, culled;
        gt_stats(w, "mitchell", "occlusion", &runs, &skipped, &culled);
        CHECK(runs == 1 && skipped == 2, "static view: occlusion runs %u (1), skipped %u (2)", runs,
              skipped);
        gt_stats(w, "mitchell", "blur", &runs, &skipped, &culled);
        CHECK(runs == 3, "static view: blur runs %u (3)", runs);
        // A moved camera redraws it.
        const float p[3] = {0.1f, 0, 5}, t[3] = {0.1f, 0, 0}, up[3] = {0, 1, 0};
        st_world_set_camera(w, p, t, up);
        gt_frames(w, 1, &img);
        gt_stats(w, "mitchell", "occlusion", &runs, &skipped, &culled);
        CHECK(runs == 2, "camera moved: occlusion runs %u (2)", runs);
    }
    st_image_free(&img);
    st_world_destroy(w);
    st_scene_free(&sc);

    // The same through the command line's --stats=json.
    gt_pass_count pc[8];
    int n = gt_cli_pass_stats(scene_json(light, "", NULL, "", NULL), "mitchell", pc, 8), seen = 0;
    CHECK(n >= 0, "strahl render --stats=json");
    for (int k = 0; k < n; k++) {
        if (!strcmp(pc[k].pass, "blur")) {
            seen++;
            CHECK(pc[k].runs == 0 && pc[k].skipped == 2, "json blur: runs %d skipped %d",
                  pc[k].runs, pc[k].skipped);
        } else if (!strcmp(pc[k].pass, "occlusion")) {
            seen++;
            CHECK(pc[k].runs == 0 && pc[k].culled == 2, "json occlusion: runs %d culled %d",
                  pc[k].runs, pc[k].culled);
        }
    }
    CHECK(seen == 2, "--stats=json lists mitchell's blur and occlusion passes (%d)", seen);
}

// ---- stress -------------------------------------------------------------------------

static int stress_scene(const char *what, const char *light_pos, const char *params) {
    char light[256];
    snprintf(light, sizeof light,
             "{\"type\": \"point\", \"position\": [%s], \"intensity\": [4, 2, 1]}", light_pos);
    st_scene sc;
    gt_scene(
        scene_json(light,
                   "{\"quad\": {\"corner\": [-3, -3, -1], \"u\": [6, 0, 0], \"v\": [0, 6, 0]}, "
                   "\"albedo\": [0.5, 0.5, 0.5]},"
                   "{\"box\": {\"min\": [-0.3, -0.3, -0.5], \"max\": [0.3, 0.3, -0.2]}, "
                   "\"emission\": [3, 3, 3]}",
                   MEDIUM, params, NULL),
        &sc);
    st_world *w = gt_world(&sc);
    st_image img = {0};
    int bad = gt_frames(w, 1, &img) ? (int)st_image_count_nonfinite(&img) : -1;
    // Every parameter at each end of its range, one at a time, then all.
    int nparam = 0;
    if (bad == 0) {
        st_module_info mi = st_world_module(w, 0);
        const st_plugin *p = mi.plugin;
        nparam = p->num_params;
        for (int k = 0; k < p->num_params && bad == 0; k++) {
            double def = mi.params[k];
            for (int end = 0; end < 2 && bad == 0; end++) {
                st_err err = {0};
                st_world_set_param(w, "mitchell", p->params[k].name,
                                   end ? p->params[k].max : p->params[k].min, &err);
                bad = gt_frames(w, 1, &img) ? (int)st_image_count_nonfinite(&img) : -1;
            }
            st_world_set_param(w, "mitchell", p->params[k].name, def, NULL);
        }
        for (int end = 0; end < 2 && bad == 0; end++) {
            for (int k = 0; k < p->num_params; k++)
                st_world_set_param(w, "mitchell", p->params[k].name,
                                   end ? p->params[k].max : p->params[k].min, NULL);
            bad = gt_frames(w, 1, &img) ? (int)st_image_count_nonfinite(&img) : -1;
        }
    }
    printf("stress %-32s %d parameter limits + all-min + all-max: %s\n", what, nparam,
           bad == 0 ? "all finite" : "NON-FINITE");
    CHECK(bad == 0, "stress %s: %d non-finite values", what, bad);
    st_image_free(&img);
    st_world_destroy(w);
    st_scene_free(&sc);
    return bad;
}

static void test_stress(void) {
    stress_scene("light at a pixel centre", "0, 0, 0", "\"resolution\": 1");
    stress_scene("light at the camera", "0, 0, 5", "");
    stress_scene("light behind the camera", "0, 0.2, 6", "");
    stress_scene("light on a surface", "0.2, 0.1, -1", "");
    stress_scene("light inside an emitter", "0, 0, -0.35", "");
    stress_scene("light within 2 near of the camera", "0, 0, 4.93", "");
    stress_scene("light on the camera plane", "1, 0, 5", "");
}

int main(void) {
    st_context *ctx = st_test_context();
    test_occlusion_content();
    test_occlusion_smooth();
    test_light_pixel();
    test_additive();
    test_fade();
    test_idle();
    test_stress();
    st_context_destroy(ctx);
    return st_test_summary("test_mitchell_scene");
}
