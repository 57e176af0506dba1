// strahl view, scripted under Xvfb: module switching by key, live parameter
// changes, camera moves, resize, screenshots and per-pass stats. Screenshots
// must equal the headless `strahl render` of the same state (within 1e-4),
// and the stats must show which passes ran or were skipped.
#include "st_test_support.h"
#include "view_test.h"

static const double LP[3] = {0, 1.8, 0};
static const double BMIN[3] = {-0.3, 0.8, -0.3}, BMAX[3] = {0.3, 1.0, 0.3};
static const double CAM[3] = {0, 3, 2.5}, TGT[3] = {0, 0, 0}, UP[3] = {0, 1, 0};
enum { W = 128, H = 96 };

static void write_scene(const char *path, const char *modules) {
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": 60,"
             " \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [3, "
             "3, 3]}],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 0, 8], \"v\": [8, 0, "
             "0]}, \"albedo\": [0.75, 0.75, 0.75]},\n"
             "   {\"box\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}}],\n"
             " \"modules\": [%s]}\n",
             W, H, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], LP[0], LP[1], LP[2], BMIN[0],
             BMIN[1], BMIN[2], BMAX[0], BMAX[1], BMAX[2], modules);
    st_test_write(path, json);
}

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
    char scene[512], scene_off[512], script[512], path[1024], cmd[2048];
    snprintf(scene, sizeof scene, "%s/basic.json", D);
    snprintf(scene_off, sizeof scene_off, "%s/basic_off.json", D);
    snprintf(script, sizeof script, "%s/basic.script", D);
    write_scene(scene, "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}}");
    write_scene(scene_off, "");

    // Headless references of the same states.
    snprintf(path, sizeof path, "%s/ref_on.exr", D);
    CHECK(st_test_render(scene, path, NULL) == 0, "render on");
    snprintf(path, sizeof path, "%s/ref_off.exr", D);
    CHECK(st_test_render(scene_off, path, NULL) == 0, "render off");
    snprintf(path, sizeof path, "%s/ref_pcf.exr", D);
    CHECK(st_test_render(scene, path, "--set shadow_map.pcf=true --set shadow_map.pcf_radius=6") ==
              0,
          "render pcf");
    snprintf(path, sizeof path, "%s/ref_small.exr", D);
    CHECK(st_test_render(scene, path, "--size 80x60") == 0, "render small");

    char key = st_view_module_key("shadow_map");
    CHECK(key != 0, "shadow_map must be one of the first ten installed modules");
    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return st_test_summary("test_view_basic");
    fprintf(
        f,
        "# first frame: everything runs\n"
        "frames 1\nstats %s/s_first.json\n"
        "frames 1\nstats %s/s_static.json\nscreenshot %s/on\n"
        "key %c\nexpect-module shadow_map off\nframes 1\nscreenshot %s/off.exr\nstats "
        "%s/s_off.json\n"
        "key %c\nexpect-module shadow_map on\nframes 1\nstats %s/s_reon.json\nscreenshot %s/on2\n"
        "orbit 25 10\nframes 1\nstats %s/s_cam.json\nscreenshot %s/cam\n"
        "camera %g %g %g %g %g %g\n"
        "set shadow_map.pcf true\nset shadow_map.pcf_radius 6\nexpect-param shadow_map.pcf_radius "
        "6\n"
        "frames 1\nstats %s/s_param.json\nscreenshot %s/pcf\n"
        "# panel keys: focus the first parameter (resolution), type a value\n"
        "key Down Enter\ntype 256\nkey Enter\nexpect-param shadow_map.resolution 256\n"
        "key Delete\nexpect-param shadow_map.resolution 512\n"
        "set shadow_map.pcf false\nset shadow_map.pcf_radius 1.5\nset shadow_map.resolution 512\n"
        "resize 80 60\nframes 1\nscreenshot %s/small\nstats %s/s_small.json\n"
        "key H\ncapture %s/window.png\n",
        D, D, D, key, D, D, key, D, D, D, D, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], D, D,
        D, D, D);
    fclose(f);
    static char log[65536];
    int rc = st_view_run(scene, script, NULL, log, sizeof log);
    CHECK(rc == 0, "strahl view --script exit code %d", rc);

    st_image on = {0}, off = {0}, on2 = {0}, cam = {0}, pcf = {0}, small = {0};
    st_image ref_on = {0}, ref_off = {0}, ref_pcf = {0}, ref_small = {0};
    st_view_read(D, "on", &on), st_view_read(D, "off", &off), st_view_read(D, "on2", &on2);
    st_view_read(D, "cam", &cam), st_view_read(D, "pcf", &pcf), st_view_read(D, "small", &small);
    st_view_read(D, "ref_on", &ref_on), st_view_read(D, "ref_off", &ref_off);
    st_view_read(D, "ref_pcf", &ref_pcf), st_view_read(D, "ref_small", &ref_small);

    // The viewer's screenshots are the headless renders of the same state.
    CHECK(st_view_max_diff(&on, &ref_on) <= 1e-4, "viewer vs render, shadow_map on: max |diff| %g",
          st_view_max_diff(&on, &ref_on));
    CHECK(st_view_max_diff(&off, &ref_off) <= 1e-4,
          "viewer vs render, shadow_map off: max |diff| %g", st_view_max_diff(&off, &ref_off));
    CHECK(st_view_max_diff(&pcf, &ref_pcf) <= 1e-4, "viewer vs render, pcf set live: max |diff| %g",
          st_view_max_diff(&pcf, &ref_pcf));
    CHECK(small.width == 80 && small.height == 60, "resized screenshot %dx%d", small.width,
          small.height);
    CHECK(st_view_max_diff(&small, &ref_small) <= 1e-4, "viewer vs render at 80x60: max |diff| %g",
          st_view_max_diff(&small, &ref_small));
    // Switching shadow_map off and on again restores the same image.
    CHECK(st_view_max_diff(&on2, &on) <= 1e-6, "on -> off -> on: max |diff| %g",
          st_view_max_diff(&on2, &on));

    // The shadowed floor: black with shadow_map, lit without it.
    st_test_cam c = st_test_camera(CAM, TGT, UP, 60, W, H);
    int shadowed = 0;
    double max_on = 0, min_off = INFINITY;
    for (int j = 0; on.data && off.data && j < H; j++)
        for (int i = 0; i < W; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            if (d[1] >= 0 || st_test_ray_box(c.pos, d, BMIN, BMAX) >= 0) continue;
            double t = -c.pos[1] / d[1], p[3];
            for (int k = 0; k < 3; k++)
                p[k] = c.pos[k] + t * d[k];
            if (st_test_shadow_state(p, 2.5 * t * 2 * c.tan_half / H, LP, BMIN, BMAX) != 1)
                continue;
            shadowed++;
            max_on = fmax(max_on, st_image_px(&on, i, j)[0]);
            min_off = fmin(min_off, st_image_px(&off, i, j)[0]);
        }
    CHECK(shadowed > 60, "shadowed floor pixels: %d", shadowed);
    CHECK(max_on == 0, "shadowed pixels with shadow_map on: max %g, expected 0", max_on);
    CHECK(min_off > 0.1, "the same pixels with shadow_map off: min %g, expected lit (> 0.1)",
          min_off);

    // A live parameter change shows: PCF with a 6-texel radius softens edges.
    int changed = st_view_count_diff(&pcf, &on, 1e-3);
    CHECK(changed > 20, "pixels changed by shadow_map.pcf: %d", changed);
    // A camera move changes the image.
    double cam_diff = st_view_count_diff(&cam, &on, 1e-3);
    CHECK(cam_diff > W * H / 4, "pixels changed by the orbit: %g", cam_diff);

    // Per-pass stats of the last frame.
    snprintf(path, sizeof path, "%s/s_first.json", D);
    cJSON *s_first = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_static.json", D);
    cJSON *s_static = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_off.json", D);
    cJSON *s_off = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_reon.json", D);
    cJSON *s_reon = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_cam.json", D);
    cJSON *s_cam = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_param.json", D);
    cJSON *s_param = st_view_json(path);
    snprintf(path, sizeof path, "%s/s_small.json", D);
    cJSON *s_small = st_view_json(path);
    CHECK(!strcmp(st_view_pass_state(s_first, "shadow_map", "cube"), "ran"),
          "frame 1: shadow cube %s", st_view_pass_state(s_first, "shadow_map", "cube"));
    CHECK(!strcmp(st_view_pass_state(s_first, "world", "regular"), "ran"), "frame 1: regular %s",
          st_view_pass_state(s_first, "world", "regular"));
    CHECK(!strcmp(st_view_pass_state(s_static, "shadow_map", "cube"), "skipped"),
          "static frame: shadow cube %s", st_view_pass_state(s_static, "shadow_map", "cube"));
    CHECK(!strcmp(st_view_pass_state(s_static, "world", "regular"), "ran"),
          "static frame: regular %s", st_view_pass_state(s_static, "world", "regular"));
    CHECK(!strcmp(st_view_pass_state(s_off, "shadow_map", "cube"), "absent"),
          "shadow_map off: cube %s", st_view_pass_state(s_off, "shadow_map", "cube"));
    CHECK(!strcmp(st_view_pass_state(s_reon, "shadow_map", "cube"), "ran"),
          "shadow_map on again: cube %s", st_view_pass_state(s_reon, "shadow_map", "cube"));
    CHECK(!strcmp(st_view_pass_state(s_cam, "shadow_map", "cube"), "skipped"),
          "camera-only move: cube %s", st_view_pass_state(s_cam, "shadow_map", "cube"));
    CHECK(!strcmp(st_view_pass_state(s_cam, "world", "regular"), "ran"),
          "camera-only move: regular %s", st_view_pass_state(s_cam, "world", "regular"));
    CHECK(!strcmp(st_view_pass_state(s_param, "shadow_map", "cube"), "ran"),
          "parameter change: cube %s", st_view_pass_state(s_param, "shadow_map", "cube"));
    double gpu = st_view_pass_num(s_first, "world", "regular", "gpu_ms");
    CHECK(gpu > 0 && gpu < 1e4, "per-pass GPU time of the regular pass: %g ms", gpu);
    double fw = s_small ? cJSON_GetNumberValue(cJSON_GetObjectItem(s_small, "width")) : 0;
    double fh = s_small ? cJSON_GetNumberValue(cJSON_GetObjectItem(s_small, "height")) : 0;
    CHECK(fw == 80 && fh == 60, "stats after resize: %gx%g", fw, fh);

    // The window capture includes the overlay at the window's size.
    int cw, ch;
    snprintf(path, sizeof path, "%s/window.png", D);
    st_view_png_size(path, &cw, &ch);
    CHECK(cw == 80 && ch == 60, "window capture %dx%d", cw, ch);
    snprintf(path, sizeof path, "%s/on.png", D);
    st_view_png_size(path, &cw, &ch);
    CHECK(cw == W && ch == H, "PNG screenshot %dx%d", cw, ch);

    printf("shadowed pixels %d (on: max %g, off: min %g), pcf changed %d px, orbit changed %g px, "
           "diffs vs render: on %g off %g pcf %g small %g\n",
           shadowed, max_on, min_off, changed, cam_diff, st_view_max_diff(&on, &ref_on),
           st_view_max_diff(&off, &ref_off), st_view_max_diff(&pcf, &ref_pcf),
           st_view_max_diff(&small, &ref_small));

    // Bad script lines stop with exit code 2 and name the line.
    snprintf(path, sizeof path, "%s/bad.script", D);
    st_test_write(path, "frames 1\nset shadow_map.bias 1000\n");
    snprintf(cmd, sizeof cmd, "%s view %s --script %s", ST_TEST_STRAHL, scene, path);
    rc = st_test_capture(log, sizeof log, cmd);
    CHECK(rc == 2, "out-of-range set: exit %d", rc);
    CHECK(strstr(log, "bad.script:2:") && strstr(log, "out of range"),
          "message names the line and the range");
    st_test_write(path, "frames 1\nexpect-module shadow_map off\n");
    rc = st_test_capture(log, sizeof log, cmd);
    CHECK(rc == 1, "failed expectation: exit %d", rc);

    cJSON *all[] = {s_first, s_static, s_off, s_reon, s_cam, s_param, s_small};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        cJSON_Delete(all[i]);
    st_image *imgs[] = {&on,    &off,    &on2,     &cam,     &pcf,
                        &small, &ref_on, &ref_off, &ref_pcf, &ref_small};
    for (size_t i = 0; i < sizeof imgs / sizeof imgs[0]; i++)
        st_image_free(imgs[i]);
    return st_test_summary("test_view_basic");
}
