// strahl view mouse input under Xvfb, through the same handlers the window's
// events call: clicking a module row switches it, dragging a slider sets a
// parameter from the pointer's position (its range from the descriptor),
// clicking a bool toggles it, dragging over the image orbits the camera, the
// wheel zooms, and the fly camera turns in place and moves along its view. The panel's control
// rectangles come from `stats`.
#include "view_test.h"

enum { W = 640, H = 400 };

static int widget(cJSON *stats, const char *module, const char *param, double r[4]) {
    cJSON *w;
    if (!stats) return 0;
    cJSON_ArrayForEach(w, cJSON_GetObjectItem(stats, "widgets")) {
        const char *m = cJSON_GetStringValue(cJSON_GetObjectItem(w, "module"));
        const char *p = cJSON_GetStringValue(cJSON_GetObjectItem(w, "param"));
        if (m && p && !strcmp(m, module) && !strcmp(p, param)) {
            const char *keys[4] = {"x", "y", "w", "h"};
            for (int k = 0; k < 4; k++)
                r[k] = cJSON_GetNumberValue(cJSON_GetObjectItem(w, keys[k]));
            return 1;
        }
    }
    return 0;
}

static double param(cJSON *stats, const char *module, const char *name) {
    cJSON *m;
    if (!stats) return NAN;
    cJSON_ArrayForEach(m, cJSON_GetObjectItem(stats, "modules")) {
        const char *n = cJSON_GetStringValue(cJSON_GetObjectItem(m, "name"));
        if (n && !strcmp(n, module))
            return cJSON_GetNumberValue(
                cJSON_GetObjectItem(cJSON_GetObjectItem(m, "params"), name));
    }
    return NAN;
}

static void camera(cJSON *stats, double pos[3], double tgt[3]) {
    cJSON *c = stats ? cJSON_GetObjectItem(stats, "camera") : NULL;
    for (int k = 0; k < 3; k++) {
        pos[k] = c ? cJSON_GetNumberValue(cJSON_GetArrayItem(cJSON_GetObjectItem(c, "position"), k))
                   : NAN;
        tgt[k] =
            c ? cJSON_GetNumberValue(cJSON_GetArrayItem(cJSON_GetObjectItem(c, "target"), k)) : NAN;
    }
}

// A press and release at (x, y) with frames between, as a click arrives.
static void click(FILE *f, double x, double y) {
    fprintf(f, "mouse %.1f %.1f\nframes 1\nbutton left down\nframes 1\nbutton left up\nframes 1\n",
            x, y);
}

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
    char scene[512], script[512], path[1024], json[2048], size[32];
    snprintf(scene, sizeof scene, "%s/mouse.json", D);
    snprintf(script, sizeof script, "%s/mouse.script", D);
    snprintf(size, sizeof size, "--size %dx%d", W, H);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 64, \"height\": 64},\n"
             " \"camera\": {\"position\": [0, 3, 2.5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 60, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.8, 0], \"intensity\": [3, 3, "
             "3]}],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 0, 8], \"v\": [8, 0, "
             "0]}, \"albedo\": [0.75, 0.75, 0.75]},\n"
             "   {\"box\": {\"min\": [-0.3, 0.8, -0.3], \"max\": [0.3, 1.0, 0.3]}}],\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}}]}\n");
    st_test_write(scene, json);
    static char log[65536];

    // Run 1: where the controls are.
    snprintf(path, sizeof path, "%s/layout.json", D);
    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return st_test_summary("test_view_mouse");
    fprintf(f, "frames 1\nstats %s\n", path);
    fclose(f);
    CHECK(st_view_run(scene, script, size, log, sizeof log) == 0, "layout run");
    cJSON *layout = st_view_json(path);
    double row[4], bias[4], pcf[4];
    int ok = widget(layout, "shadow_map", "", row) && widget(layout, "shadow_map", "bias", bias) &&
             widget(layout, "shadow_map", "pcf", pcf);
    CHECK(ok, "the panel lists shadow_map with its bias and pcf controls");
    CHECK(layout && cJSON_GetArraySize(cJSON_GetObjectItem(layout, "widgets")) >= 6,
          "widgets: module rows and 5 parameters");
    cJSON_Delete(layout);
    if (!ok) return st_test_summary("test_view_mouse");
    CHECK(bias[0] + bias[2] <= W && bias[1] + bias[3] <= H && bias[0] > W / 3,
          "bias slider inside the window, right side: x %g w %g", bias[0], bias[2]);

    // Run 2: the interactions.
    f = fopen(script, "w");
    fprintf(f, "frames 1\nstats %s/m0.json\n", D);
    click(f, row[0] + 0.5 * row[2], row[1] + 0.5 * row[3]);
    fprintf(f, "expect-module shadow_map off\n");
    click(f, row[0] + 0.5 * row[2], row[1] + 0.5 * row[3]);
    fprintf(f, "expect-module shadow_map on\n");
    // Slider: press at 25% of its width, drag to 75%, release.
    fprintf(f, "mouse %.1f %.1f\nframes 1\nbutton left down\nframes 1\nstats %s/m_press.json\n",
            bias[0] + 0.25 * bias[2], bias[1] + 0.5 * bias[3], D);
    fprintf(f, "mouse %.1f %.1f\nframes 1\nbutton left up\nframes 1\nstats %s/m_drag.json\n",
            bias[0] + 0.75 * bias[2], bias[1] + 0.5 * bias[3], D);
    click(f, pcf[0] + 2, pcf[1] + 0.5 * pcf[3]);
    fprintf(f, "expect-param shadow_map.pcf 1\n");
    // Orbit: drag 40 px to the right over the image (left of the panel).
    fprintf(f,
            "mouse 40 150\nframes 1\nbutton left down\nmouse 80 150\nframes 1\nbutton left "
            "up\nframes 1\n"
            "stats %s/m_orbit.json\nwheel 2\nframes 1\nstats %s/m_wheel.json\n"
            "key C\nexpect-message camera: fly\norbit 30 0\nframes 1\nstats %s/m_fly.json\n"
            "move 0.5 0 0\nframes 1\nstats %s/m_move.json\n",
            D, D, D, D);
    fclose(f);
    int rc = st_view_run(scene, script, size, log, sizeof log);
    CHECK(rc == 0, "mouse session exit %d", rc);

    cJSON *m0, *press, *drag, *orbit, *wheel, *fly, *move;
    snprintf(path, sizeof path, "%s/m0.json", D), m0 = st_view_json(path);
    snprintf(path, sizeof path, "%s/m_press.json", D), press = st_view_json(path);
    snprintf(path, sizeof path, "%s/m_drag.json", D), drag = st_view_json(path);
    snprintf(path, sizeof path, "%s/m_orbit.json", D), orbit = st_view_json(path);
    snprintf(path, sizeof path, "%s/m_wheel.json", D), wheel = st_view_json(path);
    snprintf(path, sizeof path, "%s/m_fly.json", D), fly = st_view_json(path);
    snprintf(path, sizeof path, "%s/m_move.json", D), move = st_view_json(path);
    // bias is a float in [0, 64] on a linear slider; half a pixel of slack.
    double slack = 64 * 0.6 / bias[2];
    CHECK_REL(param(press, "shadow_map", "bias"), 16, 0, slack);
    CHECK_REL(param(drag, "shadow_map", "bias"), 48, 0, slack);
    CHECK(!strcmp(st_view_pass_state(drag, "shadow_map", "cube"), "ran"),
          "a parameter drag re-renders the cube: %s",
          st_view_pass_state(drag, "shadow_map", "cube"));

    double p0[3], t0[3], p1[3], t1[3], p2[3], t2[3];
    camera(m0, p0, t0), camera(orbit, p1, t1), camera(wheel, p2, t2);
    double r0 = 0, r1 = 0, r2 = 0;
    for (int k = 0; k < 3; k++) {
        r0 += (p0[k] - t0[k]) * (p0[k] - t0[k]);
        r1 += (p1[k] - t1[k]) * (p1[k] - t1[k]);
        r2 += (p2[k] - t2[k]) * (p2[k] - t2[k]);
    }
    r0 = sqrt(r0), r1 = sqrt(r1), r2 = sqrt(r2);
    // 0.3 degrees per pixel around the up axis, at the same distance.
    double yaw0 = atan2(p0[2] - t0[2], p0[0] - t0[0]), yaw1 = atan2(p1[2] - t1[2], p1[0] - t1[0]);
    double dyaw = fmod((yaw1 - yaw0) * 180 / M_PI + 540, 360) - 180;
    CHECK_REL(fabs(dyaw), 12.0, 1e-3, 0);
    CHECK_REL(r1, r0, 1e-5, 0);
    CHECK_REL(p1[1], p0[1], 1e-5, 1e-6);
    CHECK(!strcmp(st_view_pass_state(orbit, "shadow_map", "cube"), "skipped"),
          "orbit: shadow cube %s", st_view_pass_state(orbit, "shadow_map", "cube"));
    // Two wheel clicks toward the scene: distance x 0.9^2.
    CHECK_REL(r2, r0 * 0.81, 1e-5, 0);
    // Fly camera: turning keeps the position and swings the target around
    // it (30 degrees of yaw); moving goes along the view direction.
    double p3[3], t3[3], p4[3], t4[3];
    camera(fly, p3, t3), camera(move, p4, t4);
    double pd = 0, v2[3], v3[3], n2 = 0, n3 = 0, dot = 0, step = 0;
    for (int k = 0; k < 3; k++) {
        pd = fmax(pd, fabs(p3[k] - p2[k]));
        v2[k] = t2[k] - p2[k], v3[k] = t3[k] - p3[k];
    }
    double yaw2 = atan2(v2[2], v2[0]), yaw3 = atan2(v3[2], v3[0]);
    double fyaw = fmod((yaw3 - yaw2) * 180 / M_PI + 540, 360) - 180;
    CHECK(pd < 1e-6, "fly turn keeps the position: moved %g", pd);
    CHECK_REL(fabs(fyaw), 30.0, 1e-3, 0);
    for (int k = 0; k < 3; k++) {
        n3 += v3[k] * v3[k];
        step += (p4[k] - p3[k]) * (p4[k] - p3[k]);
        dot += (p4[k] - p3[k]) * v3[k];
        n2 += (t4[k] - p4[k] - v3[k]) * (t4[k] - p4[k] - v3[k]);
    }
    CHECK_REL(sqrt(step), 0.5, 1e-4, 0);
    CHECK_REL(dot / sqrt(n3 * step), 1.0, 1e-5, 0);
    CHECK(sqrt(n2) < 1e-5, "the target moves with the camera: %g", sqrt(n2));
    printf("bias after press %g, after drag %g; orbit %g deg; zoom %g -> %g\n",
           param(press, "shadow_map", "bias"), param(drag, "shadow_map", "bias"), dyaw, r1, r2);
    cJSON *all[] = {m0, press, drag, orbit, wheel, fly, move};
    for (int i = 0; i < 7; i++)
        cJSON_Delete(all[i]);
    return st_test_summary("test_view_mouse");
}
