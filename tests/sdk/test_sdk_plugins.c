// Every in-tree plugin is an SDK plugin (issue 33): each modules/NAME builds
// on its own against an installed strahl (cmake -S modules/NAME with
// CMAKE_PREFIX_PATH), and the installed strahl, given that build through
// STRAHL_MODULE_PATH, renders a scene using it bit-identically (max_abs 0)
// to the in-tree build. The dynamic loader's log (LD_DEBUG=files) shows that
// the plugin came from the out-of-tree build and nothing from the build
// tree; other plugins a scene requires come from the prefix. Each plugin's
// result is printed on its own line.
#include "sdk_test.h"
#include "st_test_render.h"

#define SIZE "--size 48x48 --frames 1" // st_test_render adds --filter point

static const struct {
    const char *name, *scene; // scene: in scenes/, or NULL for ssgi's variant
} plugins[] = {
    {"shadow_map", "colonnade_sun_sousa"},
    {"atlas_gi", "gi_cornell"},
    {"mitchell", "godrays_window_mitchell"},
    {"sousa", "godrays_window_sousa"},
    {"toth", "godrays_light_front"},
    {"froxel", "godrays_window_froxel"},
    {"ssgi", NULL},
};

// No scene in scenes/ uses ssgi: the Cornell box with ssgi alone (as
// tools/check_images_unchanged.sh's variant_ssgi).
static bool write_ssgi_scene(const char *path) {
    char src[1200], text[8192];
    snprintf(src, sizeof src, "%s/scenes/cornell.json", ST_TEST_SOURCE_DIR);
    FILE *f = fopen(src, "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f) fclose(f);
    text[n] = 0;
    char *mods = strstr(text, "\"modules\"");
    if (!mods || n == sizeof text - 1) return false;
    snprintf(mods, text + sizeof text - mods,
             "\"modules\": [{\"name\": \"ssgi\", \"params\": {\"samples\": 64}}]}\n");
    st_test_write(path, text);
    return true;
}

// Whether the dynamic loader's log names a file that starts with `path`.
static bool loaded(const char *log, const char *path) {
    return st_test_sh("grep -q 'file=%s' %s", path, log) == 0;
}

// The installed strahl with the out-of-tree `modules` renders `scene`; the
// image must equal the in-tree one, bit for bit.
static bool same_render(const char *prefix, const char *modules, const char *name,
                        const char *scene, const char *dir) {
    char in[1400], oot[1400], log[1400], so[1500];
    snprintf(in, sizeof in, "%s/intree.exr", dir);
    snprintf(oot, sizeof oot, "%s/oot.exr", dir);
    snprintf(log, sizeof log, "%s/ld.log", dir);
    int rc = st_test_render(scene, in, SIZE);
    CHECK(rc == 0, "%s: the in-tree build renders %s (rc %d)", name, scene, rc);
    unlink(oot);
    int rc2 = st_test_sh("env -u STRAHL_SHADER_PATH STRAHL_MODULE_PATH=%s LD_DEBUG=files "
                         "%s/bin/strahl render %s -o %s --filter point %s 2>%s",
                         modules, prefix, scene, oot, SIZE, log);
    CHECK(rc2 == 0, "%s: the installed strahl renders %s (rc %d)", name, scene, rc2);
    snprintf(so, sizeof so, "%s/%s.so ", modules, name);
    bool from_oot = loaded(log, so);
    snprintf(so, sizeof so, "%s/modules/", ST_TEST_BINARY_DIR);
    bool from_tree = loaded(log, so);
    snprintf(so, sizeof so, "%s/lib/", ST_TEST_BINARY_DIR);
    from_tree = loaded(log, so) || from_tree;
    CHECK(from_oot && !from_tree, "%s: loaded from %s/%s.so (%d), nothing from %s (%d)", name,
          modules, name, from_oot, ST_TEST_BINARY_DIR, from_tree);
    st_image a = {0}, b = {0};
    bool same = false;
    if (!rc && !rc2 && st_test_read(in, &a) && st_test_read(oot, &b)) {
        size_t n = (size_t)a.width * a.height * a.channels;
        double max_abs = 0;
        same = a.width == b.width && a.height == b.height && a.channels == b.channels;
        for (size_t i = 0; same && i < n; i++)
            if (!(fabs((double)a.data[i] - b.data[i]) <= max_abs))
                max_abs = fabs((double)a.data[i] - b.data[i]);
        same = same && max_abs == 0 && !memcmp(a.data, b.data, n * sizeof(float));
        printf("%s: %s %dx%d, max_abs %g\n", name, scene, a.width, a.height, max_abs);
    }
    CHECK(same, "%s: out-of-tree render equals the in-tree render bit for bit", name);
    st_image_free(&a);
    st_image_free(&b);
    return same && from_oot && !from_tree;
}

int main(void) {
    char prefix[1024];
    snprintf(prefix, sizeof prefix, "%s/prefix", ST_TEST_SCRATCH);
    int rc = sdk_install(prefix);
    CHECK(rc == 0, "cmake --install (rc %d)", rc);
    char passed[256] = "", failed[256] = "";
    for (size_t k = 0; k < sizeof plugins / sizeof plugins[0]; k++) {
        const char *name = plugins[k].name;
        char src[1200], out[1200], log[1300], modules[1300], scene[1300];
        snprintf(src, sizeof src, "%s/modules/%s", ST_TEST_SOURCE_DIR, name);
        snprintf(out, sizeof out, "%s/%s", ST_TEST_SCRATCH, name);
        snprintf(log, sizeof log, "%s/%s.build.log", ST_TEST_SCRATCH, name);
        snprintf(modules, sizeof modules, "%s/modules", out);
        int b = sdk_build(src, out, prefix, log);
        CHECK(b == 0, "%s: builds out of tree against the installed SDK (rc %d; %s)", name, b, log);
        if (b) st_test_sh("tail -n 15 %s >&2", log);
        bool ok = b == 0;
        if (ok && plugins[k].scene) {
            snprintf(scene, sizeof scene, "%s/scenes/%s.json", ST_TEST_SOURCE_DIR,
                     plugins[k].scene);
        } else if (ok) {
            snprintf(scene, sizeof scene, "%s/ssgi.json", ST_TEST_SCRATCH);
            ok = write_ssgi_scene(scene);
            CHECK(ok, "ssgi: scene from scenes/cornell.json");
        }
        if (ok) ok = same_render(prefix, modules, name, scene, out);
        printf("plugin %s: %s\n", name, ok ? "PASS" : b ? "FAIL (out-of-tree build)" : "FAIL");
        char *list = ok ? passed : failed;
        size_t l = strlen(list);
        snprintf(list + l, 256 - l, " %s", name);
    }
    printf("out of tree: passed:%s; failed:%s\n", passed[0] ? passed : " none",
           failed[0] ? failed : " none");
    return st_test_summary("test_sdk_plugins");
}
