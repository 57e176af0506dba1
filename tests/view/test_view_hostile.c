// strahl view scripts as hostile input (issue 36, items 3 and 9): every file
// a script writes passes the checks of a command's -o (never the scene
// file, a file the scene was read from, or the running script), and camera
// numbers that leave the camera non-finite or without a view direction are
// refused like the scene file refuses them. Each case: exit 2, a message
// naming the culprit, the file untouched.
#include "st_test_support.h"
#include "view_test.h"

static const char *D;
static char scene[600], log_buf[65536];

// Runs a one-line script (after one frame); returns the exit code.
static int script_run(const char *script_name, const char *line) {
    char script[700];
    snprintf(script, sizeof script, "%s/%s", D, script_name);
    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return -1;
    fprintf(f, "frames 1\n%s\nquit\n", line);
    fclose(f);
    return st_view_run(scene, script, NULL, log_buf, sizeof log_buf);
}

// The file at path still has `want`.
static bool unchanged(const char *path, const char *want) {
    st_err e = {0};
    char *got = st_read_file(path, NULL, &e);
    bool same = got && !strcmp(got, want);
    free(got);
    return same;
}

#define REFUSED(rc, culprit, why, what)                                                            \
    CHECK((rc) == 2 && strstr(log_buf, culprit) && strstr(log_buf, why), "%s: exit %d, log: %s",   \
          what, rc, log_buf)

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    D = ST_TEST_SCRATCH;
    // The scene's geometry is a glTF named model.png (a data: URI buffer).
    char gltf[700], path[1600];
    snprintf(gltf, sizeof gltf, "%s/model.png", D);
    const char *model =
        "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [{\"primitives\": [{\"attributes\": "
        "{\"POSITION\": 0}}]}], \"nodes\": [{\"mesh\": 0}], \"buffers\": [{\"byteLength\": 36, "
        "\"uri\": \"data:application/octet-stream;base64,"
        "AACAvwAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}], \"bufferViews\": [{\"buffer\": 0, "
        "\"byteLength\": 36}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, "
        "\"count\": 3, \"type\": \"VEC3\", \"min\": [-1, 0, 0], \"max\": [1, 1, 0]}]}";
    st_test_write(gltf, model);
    const char *json =
        "{\"image\": {\"width\": 32, \"height\": 24}, \"camera\": {\"position\": [0, 0.5, 3], "
        "\"target\": [0, 0.5, 0], \"fov_y\": 50}, \"lights\": [{\"type\": \"point\", "
        "\"position\": [0, 2, 1], \"intensity\": [3, 3, 3]}], \"geometry\": [{\"gltf\": "
        "\"model.png\"}]}";
    snprintf(scene, sizeof scene, "%s/s.json", D);
    st_test_write(scene, json);

    // Item 3: stats over the scene, a capture over its glTF, stats over the script.
    snprintf(path, sizeof path, "stats %s", scene);
    int rc = script_run("a.script", path);
    REFUSED(rc, "s.json", "same file", "stats over the scene");
    snprintf(path, sizeof path, "capture %s", gltf);
    rc = script_run("b.script", path);
    REFUSED(rc, "model.png", "the scene", "capture over the scene's glTF");
    snprintf(path, sizeof path, "screenshot %s/model", D);
    rc = script_run("c.script", path);
    REFUSED(rc, "model.png", "the scene", "screenshot over the scene's glTF");
    snprintf(path, sizeof path, "stats %s/self.json", D);
    rc = script_run("self.json", path);
    REFUSED(rc, "self.json", "same file", "stats over the running script");
    snprintf(path, sizeof path, "capture %s/s.txt", D);
    rc = script_run("d.script", path);
    REFUSED(rc, "s.txt", ".png", "capture to a non-PNG name");
    CHECK(unchanged(scene, json) && unchanged(gltf, model), "the scene or its glTF changed");

    // Item 9: numbers that break the camera.
    rc = script_run("e.script", "dolly 1e308");
    REFUSED(rc, "dolly: '1e308'", "out of range for a float", "dolly 1e308");
    rc = script_run("f.script", "dolly 1e30\ndolly 1e30");
    REFUSED(rc, "dolly 1e30", "non-finite", "dolly 1e30 twice (finite factors, infinite camera)");
    rc = script_run("g.script", "camera 0 0 0 0 0 0");
    REFUSED(rc, "camera 0 0 0 0 0 0", "target at the position", "camera with target = position");
    rc = script_run("h.script", "move 1e38 1e38 1e38\nmove 1e38 1e38 1e38");
    // (1e38 absorbs the camera-target offset: refused as one or the other)
    REFUSED(rc, "move 1e38 1e38 1e38: ", "the ", "move to infinity");
    // A good camera line still works, and stats then holds finite numbers.
    snprintf(path, sizeof path, "camera 0 1 3 0 0.5 0\nstats %s/ok.json", D);
    rc = script_run("i.script", path);
    CHECK(rc == 0, "a good camera line: exit %d: %s", rc, log_buf);
    snprintf(path, sizeof path, "%s/ok.json", D);
    cJSON *st = st_view_json(path);
    CHECK(st != NULL, "stats after a good camera line is valid JSON");
    cJSON_Delete(st);
    return st_test_summary("test_view_hostile");
}
