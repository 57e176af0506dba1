// strahl view god-ray cycle under Xvfb: a room in a scattering medium whose
// ceiling has a square opening with the light above it. The G key cycles
// off and the installed god-ray techniques by name (the plugins that only
// add light: mitchell > sousa > toth; never shadow_map, atlas_gi or ssgi);
// toth switches shadow_map on; toth adds in-scattered light along
// the shaft under the opening and none in the shadowed medium; a live
// toth.samples change equals the headless render with that setting; and
// shadow_map cannot be switched off while toth needs it.
#include "view_test.h"

enum { N = 96 };
static const double LIGHT[3] = {0, 3.2, 0}, HOLE = 0.3, Y0 = 2.0, Y1 = 2.1;
static const double CAM[3] = {-3.0, 1.0, 3.0}, TGT[3] = {0, 0.8, 0}, UP[3] = {0, 1, 0}, FOV = 60;

static void write_scene(const char *path, const char *modules) {
    char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [20, "
             "20, 20]}],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 0, 8], \"v\": [8, 0, 0]}, "
             "\"albedo\": [0.5, 0.5, 0.5]},\n"
             "  {\"quad\": {\"corner\": [-4, 0, -4], \"u\": [8, 0, 0], \"v\": [0, 2, 0]}, "
             "\"albedo\": [0.5, 0.5, 0.5]},\n"
             "  {\"quad\": {\"corner\": [-4, 0, 4], \"u\": [0, 2, 0], \"v\": [8, 0, 0]}, "
             "\"albedo\": [0.5, 0.5, 0.5]},\n"
             "  {\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 2, 0], \"v\": [0, 0, 8]}, "
             "\"albedo\": [0.5, 0.5, 0.5]},\n"
             "  {\"quad\": {\"corner\": [4, 0, -4], \"u\": [0, 0, 8], \"v\": [0, 2, 0]}, "
             "\"albedo\": [0.5, 0.5, 0.5]},\n"
             "  {\"box\": {\"min\": [-4, %g, -4], \"max\": [4, %g, %g]}},\n"
             "  {\"box\": {\"min\": [-4, %g, %g], \"max\": [4, %g, 4]}},\n"
             "  {\"box\": {\"min\": [-4, %g, %g], \"max\": [%g, %g, %g]}},\n"
             "  {\"box\": {\"min\": [%g, %g, %g], \"max\": [4, %g, %g]}}],\n"
             " \"medium\": {\"sigma_s\": [0.3, 0.3, 0.3], \"sigma_a\": [0.05, 0.05, 0.05]},\n"
             " \"modules\": [%s]}\n",
             N, N, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], FOV, LIGHT[0], LIGHT[1],
             LIGHT[2], Y0, Y1, -HOLE, Y0, HOLE, Y1, Y0, -HOLE, -HOLE, Y1, HOLE, HOLE, Y0, -HOLE, Y1,
             HOLE, modules);
    st_test_write(path, json);
}

// Does the segment from p to the light pass the opening (both slab faces),
// with the opening grown by `grow`?
static int sees_light(const double p[3], double grow) {
    const double ys[2] = {Y0, Y1};
    if (p[1] >= Y0) return 0;
    for (int k = 0; k < 2; k++) {
        double t = (ys[k] - p[1]) / (LIGHT[1] - p[1]);
        double x = p[0] + t * (LIGHT[0] - p[0]), z = p[2] + t * (LIGHT[2] - p[2]);
        if (fabs(x) > HOLE + grow || fabs(z) > HOLE + grow) return 0;
    }
    return 1;
}

// Length of the view ray inside the room that the light reaches; the ray
// ends where it leaves the box [-4, 4] x [0, Y0] x [-4, 4] (or -1 if it
// leaves through the opening: such pixels are left out).
static double lit_length(const double o[3], const double d[3], double grow) {
    double t_exit = 1e30;
    const double mn[3] = {-4, 0, -4}, mx[3] = {4, Y0, 4};
    for (int k = 0; k < 3; k++) {
        if (fabs(d[k]) < 1e-12) continue;
        double t = ((d[k] > 0 ? mx[k] : mn[k]) - o[k]) / d[k];
        if (t < t_exit) t_exit = t;
    }
    double e[3] = {o[0] + t_exit * d[0], o[1] + t_exit * d[1], o[2] + t_exit * d[2]};
    if (e[1] >= Y0 - 1e-9 && fabs(e[0]) <= HOLE + 0.2 && fabs(e[2]) <= HOLE + 0.2) return -1;
    const int steps = 800;
    double lit = 0;
    for (int s = 0; s < steps; s++) {
        double t = (s + 0.5) * t_exit / steps,
               p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        lit += sees_light(p, grow) * t_exit / steps;
    }
    return lit;
}

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
#define FULL_MARCH "--set toth.resolution=full --set toth.interleave=1"
    char scene[512], script[512], path[1024], tmp[1024];
    snprintf(scene, sizeof scene, "%s/godrays.json", D);
    snprintf(script, sizeof script, "%s/godrays.script", D);
    write_scene(scene, "");
    CHECK(st_view_installed("toth"), "toth must be installed for this test");
    CHECK(st_view_installed("shadow_map"), "shadow_map must be installed for this test");
    if (!st_view_installed("toth") || !st_view_installed("shadow_map"))
        return st_test_summary("test_view_godrays");

    // Headless references: shadow_map + toth (default and samples = 8), shadow_map alone.
    snprintf(tmp, sizeof tmp, "%s/godrays_toth.json", D);
    write_scene(tmp, "{\"name\": \"shadow_map\"}, {\"name\": \"toth\"}");
    snprintf(path, sizeof path, "%s/ref_toth.exr", D);
    CHECK(st_test_render(tmp, path, FULL_MARCH) == 0, "render toth");
    snprintf(path, sizeof path, "%s/ref_toth8.exr", D);
    CHECK(st_test_render(tmp, path, FULL_MARCH " --set toth.samples=8") == 0,
          "render toth samples=8");
    snprintf(tmp, sizeof tmp, "%s/godrays_sm.json", D);
    write_scene(tmp, "{\"name\": \"shadow_map\"}");
    snprintf(path, sizeof path, "%s/ref_sm.exr", D);
    CHECK(st_test_render(tmp, path, NULL) == 0, "render shadow_map only");

    // The cycle is found from the plugins' descriptors: the god-ray ones,
    // never a provider (shadow_map), the GI module or ssgi.
    char cycle[16][ST_NAME_MAX];
    int ncycle = st_view_godray_modules(cycle, 16, NULL);
    const char *want[] = {"mitchell", "sousa", "toth"},
               *never[] = {"shadow_map", "atlas_gi", "ssgi"};
    for (int i = 0; i < 3; i++) {
        bool in = false, out = false;
        for (int k = 0; k < ncycle; k++)
            in |= !strcmp(cycle[k], want[i]), out |= !strcmp(cycle[k], never[i]);
        CHECK(in || !st_view_installed(want[i]), "%s is a god-ray technique", want[i]);
        CHECK(!out, "%s is not a god-ray technique", never[i]);
    }
    // G presses: one per technique before toth.
    char before_toth[16][ST_NAME_MAX];
    int nbefore = st_view_godray_modules(before_toth, 16, "toth");
    char smkey = st_view_module_key("shadow_map");
    CHECK(smkey != 0, "shadow_map has a key");
    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return st_test_summary("test_view_godrays");
    fprintf(f, "frames 1\nstats %s/s_none.json\n", D);
    int step = 0;
    for (int i = 0; i < nbefore; i++) {
        // Each technique comes up on its own, the others off.
        fprintf(f, "key G\nexpect-module %s on\nframes 1\nstats %s/s_step%d.json\n", before_toth[i],
                D, step++);
    }
    fprintf(f, "key G\nexpect-module toth on\nexpect-module shadow_map on\n");
    for (int i = 0; i < nbefore; i++)
        fprintf(f, "expect-module %s off\n", before_toth[i]);
    // Full-resolution march without interleaving: shadow edges in the
    // medium stay sharp, so shadowed rays get exactly nothing.
    fprintf(f, "set toth.resolution full\nset toth.interleave 1\n");
    fprintf(
        f,
        "frames 2\nscreenshot %s/toth\nstats %s/s_toth.json\n"
        "set toth.samples 8\nframes 1\nscreenshot %s/toth8\nset toth.samples 64\n"
        "key %c\nexpect-message required by 'toth'\nexpect-module shadow_map on\n"
        "key G\nexpect-message god rays: off\nexpect-module toth off\nexpect-module shadow_map on\n"
        "frames 1\nscreenshot %s/off\nstats %s/s_off.json\n",
        D, D, D, smkey, D, D);
    fclose(f);
    static char log[65536];
    int rc = st_view_run(scene, script, NULL, log, sizeof log);
    CHECK(rc == 0, "strahl view --script exit code %d", rc);
    step = 0;
    for (int i = 0; i < nbefore; i++) {
        snprintf(path, sizeof path, "%s/s_step%d.json", D, step++);
        cJSON *s = st_view_json(path);
        CHECK(!strcmp(st_view_str(s, "god_rays"), before_toth[i]), "god_rays %s",
              st_view_str(s, "god_rays"));
        int n = st_view_count(s, before_toth[i], "ran") +
                st_view_count(s, before_toth[i], "skipped") +
                st_view_count(s, before_toth[i], "culled");
        CHECK(n > 0, "%s passes in the frame: %d", before_toth[i], n);
        cJSON_Delete(s);
    }

    st_image toth = {0}, toth8 = {0}, off = {0}, ref_toth = {0}, ref_toth8 = {0}, ref_sm = {0};
    st_view_read(D, "toth", &toth), st_view_read(D, "toth8", &toth8), st_view_read(D, "off", &off);
    st_view_read(D, "ref_toth", &ref_toth), st_view_read(D, "ref_toth8", &ref_toth8),
        st_view_read(D, "ref_sm", &ref_sm);
    CHECK(st_view_max_diff(&toth, &ref_toth) <= 1e-4, "viewer vs render, toth: %g",
          st_view_max_diff(&toth, &ref_toth));
    CHECK(st_view_max_diff(&toth8, &ref_toth8) <= 1e-4,
          "viewer vs render, toth.samples=8 set live: %g", st_view_max_diff(&toth8, &ref_toth8));
    CHECK(st_view_max_diff(&off, &ref_sm) <= 1e-4, "viewer vs render, toth off again: %g",
          st_view_max_diff(&off, &ref_sm));
    int changed8 = st_view_count_diff(&toth8, &toth, 1e-4);
    CHECK(changed8 > 10, "pixels changed by toth.samples 64 -> 8: %d", changed8);

    // In-scattered light along the shaft, none in the shadowed medium. Over
    // pixels whose surface is black without toth: shaft pixels have > 0.3 m
    // of lit ray, dark ones miss the light even through an opening grown by
    // 0.2 m on each side.
    st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, N, N);
    double shaft_sum = 0, dark_sum = 0, dark_max = 0;
    int shaft = 0, dark = 0;
    for (int j = 0; toth.data && off.data && j < N; j++)
        for (int i = 0; i < N; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            double lit = lit_length(c.pos, d, 0), lit_wide = lit_length(c.pos, d, 0.2);
            if (lit < 0) continue;
            // Only pixels whose surface is black without toth: there the
            // difference is the in-scattered light alone (no extinction).
            double base = st_view_mean(&off, i, j, i + 1, j + 1);
            if (base != 0) continue;
            double add = st_view_mean(&toth, i, j, i + 1, j + 1) - base;
            if (lit > 0.3) {
                shaft++;
                shaft_sum += add;
            } else if (lit_wide == 0) {
                dark++;
                dark_sum += add;
                dark_max = fmax(dark_max, fabs(add));
            }
        }
    double shaft_mean = shaft ? shaft_sum / shaft : 0, dark_mean = dark ? dark_sum / dark : 0;
    CHECK(shaft > 50, "shaft pixels: %d", shaft);
    CHECK(dark > 500, "dark pixels: %d", dark);
    CHECK(shaft_mean > 1e-3, "toth adds in-scattered light along the shaft: mean %g", shaft_mean);
    CHECK(dark_max < 0.02 * shaft_mean,
          "no in-scattering in the shadowed medium: max %g (shaft mean %g)", dark_max, shaft_mean);
    printf(
        "shaft: %d px, mean added %g; dark: %d px, mean %g, max %g; samples 64->8 changed %d px\n",
        shaft, shaft_mean, dark, dark_mean, dark_max, changed8);

    // Stats: toth's passes ran; none of them once it is off.
    snprintf(path, sizeof path, "%s/s_toth.json", D);
    cJSON *s_toth = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_off.json", D);
    cJSON *s_off = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_none.json", D);
    cJSON *s_none = st_view_json(path);
    CHECK(!strcmp(st_view_str(s_none, "god_rays"), "off"), "initially off: %s",
          st_view_str(s_none, "god_rays"));
    CHECK(!strcmp(st_view_str(s_toth, "god_rays"), "toth"), "god_rays %s",
          st_view_str(s_toth, "god_rays"));
    CHECK(!strcmp(st_view_pass_state(s_toth, "toth", "march"), "ran"), "toth march %s",
          st_view_pass_state(s_toth, "toth", "march"));
    CHECK(!strcmp(st_view_pass_state(s_toth, "toth", "compose"), "ran"), "toth compose %s",
          st_view_pass_state(s_toth, "toth", "compose"));
    CHECK(!strcmp(st_view_pass_state(s_toth, "shadow_map", "cube"), "skipped"),
          "static frame: shadow cube %s", st_view_pass_state(s_toth, "shadow_map", "cube"));
    CHECK(st_view_count(s_off, "toth", "ran") == 0 &&
              !strcmp(st_view_pass_state(s_off, "toth", "march"), "absent"),
          "toth off: no toth pass");
    double g = st_view_pass_num(s_toth, "toth", "march", "gpu_ms");
    CHECK(g > 0, "toth march GPU time %g ms", g);
    cJSON_Delete(s_toth);
    cJSON_Delete(s_off);
    cJSON_Delete(s_none);
    st_image *imgs[] = {&toth, &toth8, &off, &ref_toth, &ref_toth8, &ref_sm};
    for (size_t i = 0; i < sizeof imgs / sizeof imgs[0]; i++)
        st_image_free(imgs[i]);
    // A spot light: mitchell and sousa refuse it, so G skips them (with
    // the reason) and lands on toth (after froxel, which takes spots); G goes
    // on cycling (off, the first again) instead of sticking on a refused
    // technique.
    if (st_view_installed("mitchell") || st_view_installed("sousa")) {
        char *json = st_read_file(scene, NULL, &(st_err){0});
        char *at = json ? strstr(json, "{\"type\": \"point\",") : NULL;
        CHECK(at != NULL, "the scene has a point light to turn into a spot");
        if (at) {
            char spot[8192];
            snprintf(spot, sizeof spot,
                     "%.*s{\"type\": \"spot\", \"direction\": [0, -1, 0], \"outer_angle\": "
                     "40,%s",
                     (int)(at - json), json, at + strlen("{\"type\": \"point\","));
            snprintf(tmp, sizeof tmp, "%s/godrays_spot.json", D);
            st_test_write(tmp, spot);
            snprintf(path, sizeof path, "%s/godrays_spot.script", D);
            f = fopen(path, "w");
            CHECK(f != NULL, "spot script");
            if (f) {
                // froxel (first in the cycle when installed) supports spots:
                // G lands on it, then skips mitchell and sousa to toth.
                const char *first = st_view_installed("froxel") ? "froxel" : "toth";
                if (strcmp(first, "toth"))
                    fprintf(f, "key G\nexpect-module froxel on\nexpect-ok\n");
                fprintf(f,
                        "key G\nexpect-module toth on\nexpect-message does not support spot\n"
                        "expect-ok\nkey G\nexpect-module toth off\nexpect-message god rays: "
                        "off\nkey G\nexpect-module %s on\nframes 1\n",
                        first);
                fclose(f);
                rc = st_view_run(tmp, path, NULL, log, sizeof log);
                CHECK(rc == 0, "spot scene: strahl view --script exit code %d\n%s", rc, log);
            }
        }
        free(json);
    }
    return st_test_summary("test_view_godrays");
}
