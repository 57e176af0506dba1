// llvmpipe's loop budget with exact rays (modules/toth/toth.c,
// TOTH_LLVMPIPE_REF_TRIANGLES): on a scene of ~10^5 triangles an exact ray
// walks a BVH ~1.5x deeper than on the god-ray scenes, so the 256 steps per
// ray that fit there would overrun Mesa's 65535 loop iterations and come
// back silently short. On llvmpipe toth allows 256 x depth(2368) /
// depth(n) steps there (depth(n) = log2(n / 4) + 1): more is refused with
// exit 2, an error naming toth.samples, the scene and its triangle count,
// and no image; the limit itself renders; without exact_edges the plain
// 256 applies. Off llvmpipe every case renders.
#include "toth_test.h"
#include "st_scene.h"

static const char *SCENE =
    "{\"image\": {\"width\": 16, \"height\": 12},\n"
    " \"camera\": {\"position\": [0, 1.5, 4], \"target\": [0, 0.8, 0], \"up\": [0, 1, 0],\n"
    "            \"fov_y\": 60, \"near\": 0.05, \"far\": 40},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [50, 50, 50]}],\n"
    " \"geometry\": [\n"
    "  {\"box\": {\"min\": [-3, -0.2, -3], \"max\": [3, 0, 3]}, \"albedo\": [0.6, 0.6, 0.6]},\n"
    "  {\"sphere\": {\"center\": [0, 1.5, 0], \"radius\": 0.5, \"rings\": 160, \"segments\": "
    "320},\n"
    "   \"albedo\": [0.7, 0.2, 0.2]}],\n"
    " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]},\n"
    " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}}, {\"name\": "
    "\"toth\"}]}\n";

static double depth(double n) {
    return log2(fmax(n, 4.0) / 4.0) + 1.0;
}

int main(void) {
    char scene[1024], out[1024], cmd[4096], log[8192], want[256];
    snprintf(scene, sizeof scene, "%s/toth_exact_cap.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/toth_exact_cap.exr", ST_TEST_SCRATCH);
    st_test_write(scene, SCENE);
    st_scene sc = {0};
    st_err err = {0};
    CHECK(st_scene_load(scene, &sc, &err), "load %s: %s", scene, err.msg);
    double tris = 0;
    for (int i = 0; i < sc.num_meshes; i++)
        tris += sc.meshes[i].num_triangles;
    st_scene_free(&sc);
    CHECK(tris >= 1e5, "the scene has %.0f triangles, want >= 10^5", tris);
    int max = (int)(256 * depth(2368) / depth(tris));
    CHECK(max < 256, "the limit at %.0f triangles is %d, want < 256", tris, max);
    const char *common = "--size 16x12 --frames 1 --set toth.resolution=full";
    // The limit renders (and tells whether this is llvmpipe).
    snprintf(cmd, sizeof cmd, "%s render %s -o %s --filter point %s --set toth.samples=%d --stats",
             ST_TEST_STRAHL, scene, out, common, max);
    unlink(out);
    CHECK(st_test_capture(log, sizeof log, cmd) == 0 && access(out, F_OK) == 0,
          "%d steps on %.0f triangles failed: %s", max, tris, log);
    bool llvmpipe = strstr(log, "llvmpipe") != NULL;
    // 256 steps with exact rays: refused on llvmpipe, naming what to change.
    snprintf(cmd, sizeof cmd, "%s render %s -o %s --filter point %s --set toth.samples=256",
             ST_TEST_STRAHL, scene, out, common);
    unlink(out);
    int rc = st_test_capture(log, sizeof log, cmd);
    if (llvmpipe) {
        snprintf(want, sizeof want, "(%.0f triangles)", tris);
        CHECK(rc == 2, "256 steps, %.0f triangles, llvmpipe: exit %d, want 2", tris, rc);
        CHECK(strstr(log, "toth.samples=256") && strstr(log, want) &&
                  strstr(log, "toth_exact_cap.json") && strstr(log, "toth.exact_edges=false"),
              "the error does not name the setting, scene and triangles: %s", log);
        snprintf(want, sizeof want, "toth.samples <= %d", max);
        CHECK(strstr(log, want) != NULL, "the error does not name the limit %d: %s", max, log);
        CHECK(access(out, F_OK) != 0, "an image was written");
    } else {
        CHECK(rc == 0, "256 steps on a GPU driver: exit %d: %s", rc, log);
    }
    // Without exact rays the march alone counts: 256 steps render.
    snprintf(cmd, sizeof cmd,
             "%s render %s -o %s --filter point %s --set toth.samples=256 "
             "--set toth.exact_edges=false",
             ST_TEST_STRAHL, scene, out, common);
    CHECK(st_test_capture(log, sizeof log, cmd) == 0, "256 steps without exact rays: %s", log);
    printf("%.0f triangles: at most %d steps per ray with exact rays (llvmpipe: %d)\n", tris, max,
           llvmpipe);
    return st_test_summary("toth_exact_cap");
}
