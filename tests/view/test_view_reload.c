// strahl view hot reload under Xvfb: the session runs on a copy of the
// shaders (STRAHL_SHADER_PATH), the script breaks common/regular.frag
// between frames, and the reload must fail with file:line, keep the old
// shaders (the next screenshot equals the previous one), show the error in
// the window, survive module switches while broken (the switch-on is
// rolled back, the message names the file and line), and recover once the
// file is fixed.
#include "view_test.h"

enum { W = 200, H = 150 };

// Pixels of an 8-bit RGB PNG that look like the error box (dark red).
static int red_pixels(const char *path, int *w, int *h);

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
    char scene[512], script[512], shaders[512], path[1024], json[1024];
    snprintf(scene, sizeof scene, "%s/reload.json", D);
    snprintf(script, sizeof script, "%s/reload.script", D);
    snprintf(shaders, sizeof shaders, "%s/shaders", D);
    // A grey scene: nothing red but the error box.
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [0, 2, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 50, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.5, 0], \"intensity\": [2, 2, "
             "2]}],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-3, 0, -3], \"u\": [0, 0, 6], \"v\": [6, 0, "
             "0]}, \"albedo\": [0.5, 0.5, 0.5]},\n"
             "   {\"box\": {\"min\": [-0.3, 0, -0.3], \"max\": [0.3, 0.6, 0.3]}}],\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}}]}\n",
             W, H);
    st_test_write(scene, json);
    CHECK(st_test_sh("rm -rf %s && cp -r %s/shaders %s", shaders, ST_TEST_SOURCE_DIR, shaders) == 0,
          "copy shaders");
    setenv("STRAHL_SHADER_PATH", shaders, 1);

    // The broken line goes after the last line of the file.
    snprintf(path, sizeof path, "%s/common/regular.frag", shaders);
    char *src = st_read_file(path, NULL, &(st_err){0});
    int lines = 0;
    for (const char *c = src; c && *c; c++)
        lines += *c == '\n';
    free(src);
    CHECK(lines > 10, "regular.frag has %d lines", lines);

    char key = st_view_module_key("shadow_map");
    CHECK(key != 0, "shadow_map has a key");
    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return st_test_summary("test_view_reload");
    fprintf(
        f,
        "frames 2\nscreenshot %s/before\nexpect-ok\n"
        "# break the shader mid-session, reload with the key\n"
        "sh printf 'vec3 broken = ;\\n' >> %s/common/regular.frag\n"
        "key F5\nexpect-error common/regular.frag:%d\n"
        "frames 2\nscreenshot %s/after\nstats %s/broken.json\ncapture %s/broken.png\n"
        "# a camera move renders with the old shader too\n"
        "orbit 30 0\nframes 1\nscreenshot %s/moved_old\n"
        "# switching modules while it is broken: the error, no crash\n"
        "key %c\nexpect-module shadow_map off\nexpect-message common/regular.frag:%d\nframes 1\n"
        "key %c\nexpect-module shadow_map off\nexpect-message common/regular.frag:%d\nframes 1\n"
        "# fix it and reload through the script command\n"
        "sh cp %s/shaders/common/regular.frag %s/common/regular.frag\n"
        "reload\nexpect-ok\nkey %c\nexpect-module shadow_map on\nset shadow_map.resolution 256\n"
        "key R\nframes 1\nscreenshot %s/fixed\nstats %s/fixed.json\ncapture %s/fixed.png\n"
        "orbit 30 0\nframes 1\nscreenshot %s/moved_new\n",
        D, shaders, lines + 1, D, D, D, D, key, lines + 1, key, lines + 1, ST_TEST_SOURCE_DIR,
        shaders, key, D, D, D, D);
    fclose(f);
    static char log[65536];
    int rc = st_view_run(scene, script, NULL, log, sizeof log);
    CHECK(rc == 0, "the session goes on after the failed reload: exit %d", rc);
    snprintf(path, sizeof path, "common/regular.frag:%d", lines + 1);
    CHECK(strstr(log, "shader reload failed") && strstr(log, path),
          "stderr reports the failure with %s", path);

    st_image before = {0}, after = {0}, fixed = {0}, moved_old = {0}, moved_new = {0};
    st_view_read(D, "before", &before), st_view_read(D, "after", &after),
        st_view_read(D, "fixed", &fixed);
    st_view_read(D, "moved_old", &moved_old), st_view_read(D, "moved_new", &moved_new);
    CHECK(st_view_max_diff(&after, &before) == 0, "old shader kept: max |after - before| %g",
          st_view_max_diff(&after, &before));
    CHECK(st_view_max_diff(&fixed, &before) == 0, "after the fix: max |fixed - before| %g",
          st_view_max_diff(&fixed, &before));
    CHECK(st_view_max_diff(&moved_old, &moved_new) == 0, "moved view, old vs reloaded shader: %g",
          st_view_max_diff(&moved_old, &moved_new));
    CHECK(st_view_mean(&before, 0, 0, W, H) > 0.01, "the image is lit: mean %g",
          st_view_mean(&before, 0, 0, W, H));

    snprintf(path, sizeof path, "%s/broken.json", D);
    cJSON *broken = st_view_json(path);
    snprintf(path, sizeof path, "%s/fixed.json", D);
    cJSON *ok = st_view_json(path);
    char where[64];
    snprintf(where, sizeof where, "common/regular.frag:%d", lines + 1);
    CHECK(strstr(st_view_str(broken, "error"), where) != NULL, "stats error field names %s: %s",
          where, st_view_str(broken, "error"));
    CHECK(!strcmp(st_view_str(ok, "error"), ""), "no error after the fix: %s",
          st_view_str(ok, "error"));
    CHECK(!strcmp(st_view_pass_state(broken, "world", "regular"), "ran"),
          "the regular pass still runs: %s", st_view_pass_state(broken, "world", "regular"));

    // The error is on screen: a dark red box in the window capture, gone after the fix.
    int bw, bh, fw, fh;
    snprintf(path, sizeof path, "%s/broken.png", D);
    int red_broken = red_pixels(path, &bw, &bh);
    snprintf(path, sizeof path, "%s/fixed.png", D);
    int red_fixed = red_pixels(path, &fw, &fh);
    CHECK(bw == W && bh == H, "capture size %dx%d", bw, bh);
    CHECK(red_broken > W * H / 20, "error box pixels while broken: %d", red_broken);
    CHECK(red_fixed == 0, "error box pixels after the fix: %d", red_fixed);
    printf("regular.frag:%d reported; red error-box pixels %d broken, %d fixed\n", lines + 1,
           red_broken, red_fixed);

    cJSON_Delete(broken);
    cJSON_Delete(ok);
    st_image *imgs[] = {&before, &after, &fixed, &moved_old, &moved_new};
    for (size_t i = 0; i < sizeof imgs / sizeof imgs[0]; i++)
        st_image_free(imgs[i]);
    return st_test_summary("test_view_reload");
}

#include <stb_image.h>

static int red_pixels(const char *path, int *w, int *h) {
    int comp;
    unsigned char *px = stbi_load(path, w, h, &comp, 3);
    if (!px) {
        *w = *h = 0;
        return -1;
    }
    int n = 0;
    for (int k = 0; k < *w * *h; k++) {
        const unsigned char *p = px + 3 * k;
        n += p[0] > 70 && p[0] > 3 * p[1] && p[0] > 3 * p[2];
    }
    stbi_image_free(px);
    return n;
}
