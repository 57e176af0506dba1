// The sousa plugin in scenes (in-process worlds; the shafts are the image
// minus the same scene rendered without medium):
// - end to end: a wall perpendicular to the view with a hole (mask 8/far on
//   the wall, 1 in the hole), light seen through the hole: the shafts match
//   the C chain (tests/mitchell/godray_test.h) on that mask within 1e-3;
// - several lights add up;
// - off screen and behind the camera: continuous fade to exactly 0, then the
//   last pass is skipped and the mask culled;
// - no medium / sigma_s = 0 / brightness 0 / black light: nothing runs (also
//   in --stats=json); a static view computes mask, blur 1 and 2 once;
// - stress: light at a pixel centre, at the camera, behind it, on a surface;
//   every parameter at its range limits: all finite.
#include "st_test_support.h"
#include "mitchell/godray_test.h"
#include "st_godray.h"
#include <cjson/cJSON.h>

#define RES 40
static char json[8192];
static const char *MEDIUM = "{\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]}";

static const char *scene_json(const char *lights, const char *geometry, const char *medium,
                              const char *params, const char *camera_pos) {
    char cam[256];
    snprintf(cam, sizeof cam,
             "{\"position\": [%s], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 40, "
             "\"near\": 0.05, \"far\": 100}",
             camera_pos ? camera_pos : "0, 0, 5");
    return gt_scene_json(json, sizeof json, RES, cam, lights, geometry, medium, "sousa", params);
}

// Wall at z = -3 (8 m from the camera, perpendicular to the view) with a
// hole x in [-0.5, 0.5], y in [0.3, 1.0]; no edge passes a pixel centre.
static const char *WALL =
    "{\"quad\": {\"corner\": [-4, -4, -3], \"u\": [3.5, 0, 0], \"v\": [0, 8, 0]}},"
    "{\"quad\": {\"corner\": [0.5, -4, -3], \"u\": [3.5, 0, 0], \"v\": [0, 8, 0]}},"
    "{\"quad\": {\"corner\": [-0.5, -4, -3], \"u\": [1, 0, 0], \"v\": [0, 4.3, 0]}},"
    "{\"quad\": {\"corner\": [-0.5, 1, -3], \"u\": [1, 0, 0], \"v\": [0, 3, 0]}}";

// The scene with and without the module (effect = the difference).
static bool render_effect(const char *lights, const char *geometry, const char *params,
                          gt_pair *r) {
    char with[sizeof json];
    snprintf(with, sizeof with, "%s", scene_json(lights, geometry, MEDIUM, params, NULL));
    bool ok = gt_render_pair(with, scene_json(lights, geometry, MEDIUM, NULL, NULL), r);
    CHECK(ok && st_test_all_finite(&r->with), "finite output");
    return ok;
}

static void test_end_to_end(int taps, float brightness) {
    const char *light =
        "{\"type\": \"point\", \"position\": [0.1, 0.7, -6], \"intensity\": [2, 1.6, 1]}";
    char params[128];
    snprintf(params, sizeof params, "\"taps\": %d, \"brightness\": %g, \"resolution\": 1", taps,
             brightness);
    gt_pair r;
    if (!render_effect(light, WALL, params, &r)) return;
    // The mask the plugin should see: 8/far on the wall, 1 in the hole
    // (pixel centres; GL orientation, row 0 at the bottom).
    const double t = tan(20 * M_PI / 180);
    gimg mask = gimg_new(RES, RES, 1), zero = gimg_new(RES, RES, 4), ref = gimg_new(RES, RES, 4);
    int hole = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            double wx = (2.0 * (x + 0.5) / RES - 1) * t * 8,
                   wy = (2.0 * (y + 0.5) / RES - 1) * t * 8;
            bool in = wx > -0.5 && wx < 0.5 && wy > 0.3 && wy < 1.0;
            hole += in;
            gimg_at(&mask, x, y)[0] = in ? 1.0f : 8.0f / 100.0f;
        }
    const float tint[3] = {1, 0.8f, 0.5f};
    ref_sousa(&mask, &zero, r.light.uv, taps, brightness, tint, r.light.fade, &ref);
    double worst = 0, peak = 0;
    for (int j = 0; j < RES; j++)
        for (int i = 0; i < RES; i++)
            for (int c = 0; c < 3; c++) {
                double e = st_image_px(&r.effect, i, j)[c], x = gimg_at(&ref, i, RES - 1 - j)[c];
                worst = fmax(worst, fabs(e - x) / fmax(1, fabs(x)));
                peak = fmax(peak, x);
            }
    printf(
        "end to end, TAPS %d, brightness %.2f: %d hole pixels, light uv (%.3f, %.3f), fade %.2f, "
        "largest shaft %.3f, max |gpu - C| / max(1, |C|) = %.3g\n",
        taps, brightness, hole, r.light.uv[0], r.light.uv[1], r.light.fade, peak, worst);
    CHECK(hole > 20 && r.light.fade == 1, "setup: %d hole pixels, fade %g", hole, r.light.fade);
    CHECK(peak > 0.1, "shafts visible: %g", peak);
    CHECK(worst < 1e-3, "end to end vs C: %g", worst);
    free(mask.px), free(zero.px), free(ref.px);
    gt_pair_free(&r);
}

static void test_additive(void) {
    const char *l1 =
        "{\"type\": \"point\", \"position\": [0.1, 0.7, -6], \"intensity\": [1, 1, 1]}";
    const char *l2 =
        "{\"type\": \"point\", \"position\": [-1.5, -0.8, -6], \"intensity\": [1, 0.5, 0.2]}";
    char both[512];
    snprintf(both, sizeof both, "%s, %s", l1, l2);
    gt_pair a, b, ab;
    const char *params = "\"resolution\": 0.5";
    if (!render_effect(l1, WALL, params, &a) || !render_effect(l2, WALL, params, &b) ||
        !render_effect(both, WALL, params, &ab))
        return;
    double worst = 0, peak = 0;
    for (int i = 0; i < RES * RES * 3; i++) {
        worst = fmax(worst, fabs(ab.effect.data[i] - a.effect.data[i] - b.effect.data[i]));
        peak = fmax(peak, ab.effect.data[i]);
    }
    printf("two lights: max |shafts(1+2) - shafts(1) - shafts(2)| = %.3g (peak %.3g)\n", worst,
           peak);
    CHECK(peak > 0.05, "shafts visible: %g", peak);
    CHECK(worst < 1e-5 * fmax(1, peak), "lights add up: %g", worst);
    gt_pair_free(&a), gt_pair_free(&b), gt_pair_free(&ab);
}

// ---- fading -------------------------------------------------------------------

static void check_sweep(const char *what, int steps, void (*pose)(double, double[3], double[3])) {
    // Open sky (mask 1) around a small occluder: shafts everywhere.
    const char *light = "{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [1, 1, 1]}";
    const char *geo = "{\"box\": {\"min\": [-0.5, -0.1, -1], \"max\": [0.5, 0.1, -0.9]}}";
    char with[8192];
    snprintf(with, sizeof with, "%s", scene_json(light, geo, MEDIUM, "\"resolution\": 0.5", NULL));
    gt_check_sweep(what, "sousa", "blur3", "mask", with, scene_json(light, geo, MEDIUM, NULL, NULL),
                   steps, pose);
}

static void test_fade(void) {
    check_sweep("slide off screen", 30, godray_pose_slide);
    check_sweep("turn around", 30, godray_pose_turn);
    check_sweep("walk past the light", 30, godray_pose_walk);
}

// ---- nothing runs that the scene does not need ----------------------------------

static void expect_idle(const char *what, const char *lights, const char *medium,
                        const char *params) {
    st_scene sc, base;
    gt_scene(scene_json(lights, WALL, medium, params, NULL), &sc);
    gt_scene(scene_json(lights, WALL, medium, NULL, NULL), &base);
    st_world *w = gt_world(&sc), *wb = gt_world(&base);
    st_image a = {0}, b = {0};
    if (gt_frames(w, 3, &a) && gt_frames(wb, 1, &b)) {
        unsigned runs, skipped, culled;
        int n = gt_stats(w, "sousa", "blur3", &runs, &skipped, &culled);
        CHECK(n == sc.num_lights && runs == 0 && skipped == 3u * n, "%s: blur3 runs %u skipped %u",
              what, runs, skipped);
        const char *culled_passes[3] = {"mask", "blur1", "blur2"};
        for (int k = 0; k < 3; k++) {
            n = gt_stats(w, "sousa", culled_passes[k], &runs, &skipped, &culled);
            CHECK(n > 0 && runs == 0 && culled == 3u * n, "%s: %s runs %u culled %u", what,
                  culled_passes[k], runs, culled);
        }
        CHECK(gt_image_max_diff(&a, &b) == 0, "%s: image unchanged", what);
        printf("idle (%s): blur3 skipped; mask, blur1, blur2 culled; image identical\n", what);
    }
    st_image_free(&a), st_image_free(&b);
    st_world_destroy(w), st_world_destroy(wb);
    st_scene_free(&sc), st_scene_free(&base);
}

static void test_idle(void) {
    const char *light =
        "{\"type\": \"point\", \"position\": [0.1, 0.7, -6], \"intensity\": [1, 1, 1]}";
    expect_idle("no medium", light, NULL, "");
    expect_idle("sigma_s = 0", light, "{\"sigma_s\": [0, 0, 0]}", "");
    expect_idle("brightness 0", light, MEDIUM, "\"brightness\": 0");
    expect_idle("light behind the camera",
                "{\"type\": \"point\", \"position\": [0, 0, 9], \"intensity\": [1, 1, 1]}", MEDIUM,
                "");
    expect_idle("black light",
                "{\"type\": \"point\", \"position\": [0.1, 0.7, -6], \"intensity\": [0, 0, 0]}",
                MEDIUM, "");
    char two[512];
    snprintf(two, sizeof two,
             "%s, {\"type\": \"point\", \"position\": [0, 0, 9], \"intensity\": [1, 1, 1]}", light);
    {
        // One light on screen, one behind: only the second chain is idle.
        st_scene sc;
        gt_scene(scene_json(two, WALL, MEDIUM, "", NULL), &sc);
        st_world *w = gt_world(&sc);
        st_image img = {0};
        if (gt_frames(w, 1, &img)) {
            const char *names[4] = {"blur1[1]", "blur2[1]", "blur3[1]", "blur3[0]"};
            unsigned runs[4] = {0}, skipped[4] = {0}, culled[4] = {0};
            for (int i = 0; i < st_world_num_pass_stats(w); i++) {
                const st_pass_stats *s = st_world_pass_stats(w, i);
                for (int k = 0; k < 4; k++)
                    if (!strcmp(s->module, "sousa") && !strcmp(s->pass, names[k]))
                        runs[k] = s->runs, skipped[k] = s->skipped, culled[k] = s->culled;
            }
            CHECK(culled[0] == 1 && culled[1] == 1 && skipped[2] == 1 && runs[3] == 1,
                  "light behind: its chain is culled/skipped (%u %u %u), the visible light's runs "
                  "(%u)",
                  culled[0], culled[1], skipped[2], runs[3]);
        }
        st_image_free(&img);
        st_world_destroy(w);
        st_scene_free(&sc);
    }

    // A static view: the mask and the first two blurs run once and are reused.
    st_scene sc;
    gt_scene(scene_json(light, WALL, MEDIUM, "", NULL), &sc);
    st_world *w = gt_world(&sc);
    st_image first = {0}, img = {0};
    if (gt_frames(w, 1, &first) && gt_frames(w, 2, &img)) {
        unsigned runs[4], skipped, culled;
        const char *names[4] = {"mask", "blur1", "blur2", "blur3"};
        for (int k = 0; k < 4; k++)
            gt_stats(w, "sousa", names[k], &runs[k], &skipped, &culled);
        CHECK(runs[0] == 1 && runs[1] == 1 && runs[2] == 1 && runs[3] == 3,
              "static view over 3 frames: mask %u, blur1 %u, blur2 %u (1 each), blur3 %u (3)",
              runs[0], runs[1], runs[2], runs[3]);
        CHECK(gt_image_max_diff(&first, &img) == 0, "reused passes give the same image");
        const float p[3] = {0.1f, 0, 5}, t[3] = {0.1f, 0, 0}, up[3] = {0, 1, 0};
        st_world_set_camera(w, p, t, up);
        gt_frames(w, 1, &img);
        for (int k = 0; k < 4; k++)
            gt_stats(w, "sousa", names[k], &runs[k], &skipped, &culled);
        CHECK(runs[0] == 2 && runs[1] == 2 && runs[2] == 2,
              "camera moved: mask/blur1/blur2 rerun (%u %u %u)", runs[0], runs[1], runs[2]);
        printf("static view: mask, blur1, blur2 ran once in 3 frames, again after a camera move\n");
    }
    st_image_free(&first), st_image_free(&img);
    st_world_destroy(w);
    st_scene_free(&sc);

    // --stats=json of the command line, no medium.
    gt_pass_count pc[8];
    int seen = gt_cli_pass_stats(scene_json(light, WALL, NULL, "", NULL), "sousa", pc, 8);
    CHECK(seen >= 0, "strahl render --stats=json");
    for (int k = 0; k < seen; k++) {
        if (!strcmp(pc[k].pass, "blur3")) {
            CHECK(pc[k].runs == 0 && pc[k].skipped == 2, "json %s: runs %d skipped %d", pc[k].pass,
                  pc[k].runs, pc[k].skipped);
        } else {
            CHECK(pc[k].runs == 0 && pc[k].culled == 2, "json %s: runs %d culled %d", pc[k].pass,
                  pc[k].runs, pc[k].culled);
        }
    }
    CHECK(seen == 4, "--stats=json lists sousa's 4 passes (%d)", seen);
}

// ---- stress ---------------------------------------------------------------------

static void stress_scene(const char *what, const char *light_pos, const char *camera_pos) {
    char light[256];
    snprintf(light, sizeof light,
             "{\"type\": \"point\", \"position\": [%s], \"intensity\": [4, 2, 1]}", light_pos);
    st_scene sc;
    gt_scene(scene_json(light, WALL, MEDIUM, "", camera_pos), &sc);
    st_world *w = gt_world(&sc);
    st_image img = {0};
    int bad = gt_frames(w, 1, &img) ? (int)st_image_count_nonfinite(&img) : -1;
    st_module_info mi = st_world_module(w, 0);
    const st_plugin *p = mi.plugin;
    for (int k = 0; k < p->num_params && bad == 0; k++) {
        double def = mi.params[k];
        for (int end = 0; end < 2 && bad == 0; end++) {
            st_world_set_param(w, "sousa", p->params[k].name,
                               end ? p->params[k].max : p->params[k].min, NULL);
            bad = gt_frames(w, 1, &img) ? (int)st_image_count_nonfinite(&img) : -1;
        }
        st_world_set_param(w, "sousa", p->params[k].name, def, NULL);
    }
    for (int end = 0; end < 2 && bad == 0; end++) {
        for (int k = 0; k < p->num_params; k++)
            st_world_set_param(w, "sousa", p->params[k].name,
                               end ? p->params[k].max : p->params[k].min, NULL);
        bad = gt_frames(w, 1, &img) ? (int)st_image_count_nonfinite(&img) : -1;
    }
    printf("stress %-34s %d parameter limits + all-min + all-max: %s\n", what, p->num_params,
           bad == 0 ? "all finite" : "NON-FINITE");
    CHECK(bad == 0, "stress %s: %d non-finite values", what, bad);
    st_image_free(&img);
    st_world_destroy(w);
    st_scene_free(&sc);
}

static void test_stress(void) {
    // RES is even: the view axis hits a pixel corner; shift the light by half
    // a pixel (8 tan 20 / RES at the wall's distance... here at z = -6: 11 m).
    char centre[64];
    double half_px = 11 * tan(20 * M_PI / 180) / RES;
    snprintf(centre, sizeof centre, "%.9f, %.9f, -6", half_px, half_px);
    stress_scene("light at a pixel centre", centre, NULL);
    stress_scene("light at the camera", "0, 0, 5", NULL);
    stress_scene("light behind the camera", "0, 0.2, 6", NULL);
    stress_scene("light on the wall", "-1, -1, -3", NULL);
    stress_scene("light in the hole's plane", "0, 0.6, -3", NULL);
    stress_scene("light within 2 near of the camera", "0, 0, 4.93", NULL);
    stress_scene("light on the camera plane", "1, 0, 5", NULL);
    stress_scene("camera on the light's axis, far", "0, 0, -90", "0, 0, 5");
}

int main(void) {
    st_context *ctx = st_test_context();
    test_end_to_end(6, 0.19f);
    test_end_to_end(4, 0.3f);
    test_end_to_end(12, 0.1f);
    test_additive();
    test_fade();
    test_idle();
    test_stress();
    st_context_destroy(ctx);
    return st_test_summary("test_sousa_scene");
}
