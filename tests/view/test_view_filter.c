// strahl view with the box filter, scripted under Xvfb: while camera and
// parameters are still, frames accumulate (the stats' "accumulated" count
// grows) until converged, and the screenshot then equals the headless
// `strahl render` of the scene (the same frames, the same rule); a camera
// move or a parameter change starts again, an exposure change does not.
#include "st_test_support.h"
#include "view_test.h"
#include "st_world.h"

static int accumulated(const char *dir, const char *name, bool *done) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.json", dir, name);
    cJSON *j = st_view_json(path);
    int n = -1;
    *done = false;
    if (j) {
        cJSON *a = cJSON_GetObjectItem(j, "accumulated"),
              *d = cJSON_GetObjectItem(j, "accumulation_done");
        n = a ? a->valueint : -1;
        *done = d && cJSON_IsTrue(d);
        cJSON_Delete(j);
    }
    return n;
}

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
    char scene[512], script[512], path[1024];
    snprintf(scene, sizeof scene, "%s/filter.json", D);
    snprintf(script, sizeof script, "%s/filter.script", D);
    const double lp[3] = {0, 1.8, 0}, bmin[3] = {-0.3, 0.8, -0.3}, bmax[3] = {0.3, 1.0, 0.3};
    st_test_write_shadow_scene(scene, lp, 3, 0.75, bmin, bmax,
                               "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}}");
    snprintf(path, sizeof path, "%s/ref_box.exr", D);
    CHECK(st_test_render(scene, path, "--filter box") == 0, "render box");

    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return st_test_summary("test_view_filter");
    fprintf(f,
            "frames 5\nstats %s/s5.json\n"
            "frames 200\nstats %s/s_done.json\nscreenshot %s/box\n"
            "exposure 1\nframes 1\nstats %s/s_exposure.json\n"
            "orbit 10 0\nframes 1\nstats %s/s_orbit.json\nframes 3\nstats %s/s_orbit3.json\n"
            "set shadow_map.pcf true\nframes 1\nstats %s/s_param.json\n",
            D, D, D, D, D, D, D);
    fclose(f);
    static char log[65536];
    int rc = st_view_run(scene, script, "--filter box", log, sizeof log);
    CHECK(rc == 0, "strahl view --script exit code %d", rc);

    bool done;
    int n = accumulated(D, "s5", &done);
    CHECK(n == 5 && !done, "after 5 frames: %d accumulated (done %d)", n, done);
    int n_done = accumulated(D, "s_done", &done);
    CHECK(n_done > 5 && n_done <= ST_FILTER_MAX_FRAMES && done,
          "after 205 frames: %d accumulated (done %d)", n_done, done);
    n = accumulated(D, "s_exposure", &done);
    CHECK(n == n_done && done, "exposure change: %d accumulated (done %d)", n, done);
    n = accumulated(D, "s_orbit", &done);
    CHECK(n == 1 && !done, "after a camera move: %d accumulated", n);
    n = accumulated(D, "s_orbit3", &done);
    CHECK(n == 4, "3 frames later: %d accumulated", n);
    n = accumulated(D, "s_param", &done);
    CHECK(n == 1, "after a parameter change: %d accumulated", n);

    st_image box = {0}, ref = {0};
    st_view_read(D, "box", &box), st_view_read(D, "ref_box", &ref);
    CHECK(box.data && ref.data && st_view_max_diff(&box, &ref) <= 1e-4,
          "converged viewer vs render --filter box: max |diff| %g", st_view_max_diff(&box, &ref));
    st_image_free(&box);
    st_image_free(&ref);
    return st_test_summary("test_view_filter");
}
