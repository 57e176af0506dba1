// Every kind of bad input: exit code 2, one message line naming the culprit,
// and no output file.
#include "st_test_render.h"

static char buf[1 << 14];
static char scene[512], out[512];

static const char *GOOD_HEAD =
    "{\"image\": {\"width\": 16, \"height\": 16},"
    " \"camera\": {\"position\": [0, 1, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "50, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.5, 0], \"intensity\": [1, 1, 1]}],"
    " \"geometry\": [{\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 0, 2], \"v\": [2, 0, 0]}}]";

// Runs `strahl render` on `json` (NULL: keep the scene file) with extra
// args and env; expects exit 2, `culprit` in the one-line message, no output.
static void expect_refused(const char *what, const char *json, const char *env, const char *extra,
                           const char *culprit, int want_rc) {
    if (json) st_test_write(scene, json);
    unlink(out);
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s %s render %s -o %s %s", env ? env : "", ST_TEST_STRAHL, scene,
             out, extra ? extra : "");
    int rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == want_rc, "%s: exit code %d, want %d", what, rc, want_rc);
    CHECK(strstr(buf, culprit) != NULL, "%s: message names '%s': %s", what, culprit, buf);
    int lines = 0;
    for (char *p = buf; *p; p++)
        lines += *p == '\n';
    CHECK(lines == 1, "%s: one message line, got %d", what, lines);
    CHECK(!st_test_exists(out), "%s: no output file", what);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/bad.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/bad-out.exr", ST_TEST_SCRATCH);
    char json[4096];

    // The good scene renders (so the refusals below are about the change).
    snprintf(json, sizeof json, "%s}", GOOD_HEAD);
    st_test_write(scene, json);
    CHECK(st_test_render(scene, out, NULL) == 0 && st_test_exists(out), "good scene renders");

    expect_refused("malformed JSON", "{\"image\": {\"width\": 16,", NULL, NULL, "bad.json", 2);
    snprintf(json, sizeof json, "%s, \"colour\": 1}", GOOD_HEAD);
    expect_refused("unknown key", json, NULL, NULL, "colour", 2);
    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"nosuch\"}]}", GOOD_HEAD);
    expect_refused("unknown module", json, NULL, NULL, "nosuch", 2);
    // A technique refuses a light type it cannot handle, naming both.
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": 16, \"height\": 16},"
        " \"camera\": {\"position\": [0, 1, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
        "\"fov_y\": 50},"
        " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.5, 0], \"intensity\": [1, 1, 1]},"
        " {\"type\": \"spot\", \"position\": [0, 1.5, 0], \"direction\": [0, -1, 0], "
        "\"intensity\": [1, 1, 1]}],"
        " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1]}, \"modules\": [{\"name\": \"sousa\"}]}");
    expect_refused("light type", json, NULL, NULL,
                   "lights[1]: module 'sousa' does not support spot lights (it supports: point, "
                   "directional)",
                   2);
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": 16, \"height\": 16},"
        " \"camera\": {\"position\": [0, 1, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
        "\"fov_y\": 50},"
        " \"lights\": [{\"type\": \"spot\", \"position\": [0, 1.5, 0], \"direction\": [0, -1, 0], "
        "\"intensity\": [1, 1, 1]}],"
        " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1]}, \"modules\": [{\"name\": \"mitchell\"}]}");
    expect_refused("light type", json, NULL, NULL,
                   "lights[0]: module 'mitchell' does not support spot lights", 2);
    snprintf(json, sizeof json,
             "%s, \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"nope\": 1}}]}",
             GOOD_HEAD);
    expect_refused("unknown parameter", json, NULL, NULL, "nope", 2);
    snprintf(json, sizeof json,
             "%s, \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 5}}]}",
             GOOD_HEAD);
    expect_refused("parameter out of range", json, NULL, NULL, "resolution", 2);
    snprintf(json, sizeof json,
             "%s, \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"pcf\": \"yes\"}}]}",
             GOOD_HEAD);
    expect_refused("parameter of wrong type", json, NULL, NULL, "pcf", 2);
    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"../shadow_map\"}]}", GOOD_HEAD);
    expect_refused("module given as a path", json, NULL, NULL, "../shadow_map", 2);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 16, \"height\": 16},"
             " \"camera\": {\"position\": [0, 1, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 50, \"near\": 0.05, \"far\": 100},"
             " \"geometry\": [{\"gltf\": \"missing-asset.glb\"}]}");
    expect_refused("missing asset", json, NULL, NULL, "missing-asset.glb", 2);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 16, \"height\": 16},"
             " \"camera\": {\"position\": [0, 1, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 50, \"near\": 0.05, \"far\": 100},"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.5, 0], \"intensity\": "
             "[1e999, 1, 1]}], \"geometry\": []}");
    expect_refused("infinite value", json, NULL, NULL, "intensity", 2);

    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"shadow_map\"}]}", GOOD_HEAD);
    expect_refused("--set unknown module", json, NULL, "--set nosuch.x=1", "nosuch", 2);
    expect_refused("--set out of range", NULL, NULL, "--set shadow_map.bias=-1", "bias", 2);
    expect_refused("--size", NULL, NULL, "--size 0x5", "--size", 2);
    expect_refused("--frames", NULL, NULL, "--frames zero", "--frames", 2);
    {
        char bad_out[600];
        snprintf(bad_out, sizeof bad_out, "-o %s/x.jpg", ST_TEST_SCRATCH);
        expect_refused("output extension", NULL, NULL, bad_out, "x.jpg", 2);
    }
    unlink(scene);
    expect_refused("missing scene file", NULL, NULL, NULL, "bad.json", 2);

    // A shader that fails to compile: message names the file and line.
    char shaders[600], env[800];
    snprintf(shaders, sizeof shaders, "%s/shaders-broken", ST_TEST_SCRATCH);
    st_test_sh(
        "rm -rf %s && cp -r %s/shaders %s && printf 'void broken( {\\n' >> %s/common/regular.frag",
        shaders, ST_TEST_SOURCE_DIR, shaders, shaders);
    snprintf(env, sizeof env, "STRAHL_SHADER_PATH=%s", shaders);
    snprintf(json, sizeof json, "%s}", GOOD_HEAD);
    expect_refused("shader compile error", json, env, NULL, "shaders/common/regular.frag:", 2);

    // Plugins built wrong are refused by name.
    snprintf(env, sizeof env, "STRAHL_MODULE_PATH=%s", ST_TEST_BAD_MODULES);
    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"bad_abi_major\"}]}", GOOD_HEAD);
    expect_refused("ABI major", json, env, NULL, "module 'bad_abi_major'", 2);
    CHECK(strstr(buf, "ABI 2.0") != NULL, "names the ABI: %s", buf);
    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"bad_abi_newer_minor\"}]}",
             GOOD_HEAD);
    expect_refused("newer ABI minor", json, env, NULL, "module 'bad_abi_newer_minor'", 2);
    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"bad_missing_hooks\"}]}", GOOD_HEAD);
    expect_refused("missing hooks", json, env, NULL,
                   "missing required hook(s): create, destroy, num_passes", 2);
    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"bad_frame_size\"}]}", GOOD_HEAD);
    expect_refused("larger st_frame", json, env, NULL, "built with a different st_frame", 2);
    snprintf(json, sizeof json, "%s, \"modules\": [{\"name\": \"bad_pass_info_size\"}]}",
             GOOD_HEAD);
    expect_refused("other st_pass_info", json, env, NULL, "built with a different st_pass_info", 2);
    return st_test_summary("test_bad_input");
}
