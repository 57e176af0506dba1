// Switching modules on and off in a running world (the viewer's path) must
// never change what a module reads as its parameters. Part 1: three probe
// plugins (probe_c orders itself after probe_a when it is loaded, so
// switching probe_a on re-sorts the list) are switched on in every order and
// off in every order; after each switch every loaded probe gets new values,
// and the test checks the value the plugin reads through the pointer create()
// received, st_world_get_param, and the probe's channel of the rendered image.
// Part 2: the real plugins shadow_map, ssgi, mitchell and sousa are switched
// in two orders with parameters set in between; after each step the image
// must equal that of a world created fresh with the same modules, order and
// parameters, and with every module switched off the GPU memory is back
// where it started (the targets mitchell and sousa declare are the world's).
#include "st_test_render.h"
#include "st_test_support.h"
#include "st_world.h"
#include <dlfcn.h>

static const char *probes[3] = {"probe_a", "probe_b", "probe_c"};
typedef bool (*seen_fn)(double out[2]);
static seen_fn seen[3];

static const char *probe_scene =
    "{\"image\": {\"width\": 8, \"height\": 8},\n"
    " \"camera\": {\"position\": [0, 0, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0],"
    " \"fov_y\": 40, \"near\": 0.05, \"far\": 100},\n"
    " \"lights\": [], \"geometry\": [], \"modules\": []}\n";

static bool frame_pixel(st_world *w, float out[3]) {
    st_err err = {0};
    st_image img = {0};
    bool ok = st_world_frame(w, &err) && st_world_read(w, &img, &err);
    CHECK(ok, "frame: %s", err.msg);
    if (ok) memcpy(out, st_image_px(&img, 4, 4), 3 * sizeof(float));
    st_image_free(&img);
    return ok;
}

// One on-order and one off-order: after each switch, new values for every
// loaded probe, then every check.
static void probe_sequence(const st_scene *sc, const int on[3], const int off[3], int *counter) {
    st_err err = {0};
    st_world *w = st_world_create(sc, NULL, &err);
    CHECK(w != NULL, "world: %s", err.msg);
    if (!w) return;
    bool loaded[3] = {0};
    double value[3] = {0}, other[3] = {7, 7, 7};
    for (int step = 0; step < 6; step++) {
        int m = step < 3 ? on[step] : off[step - 3];
        bool ok = st_world_enable(w, probes[m], step < 3, &err);
        CHECK(ok, "enable %s: %s", probes[m], err.msg);
        loaded[m] = step < 3;
        if (step < 3) value[m] = 0, other[m] = 7; // a fresh instance starts at the defaults
        // New values for every loaded probe but one, so a stale pointer shows
        // either as a missed write or as a neighbour's value.
        for (int k = 0; k < 3; k++) {
            if (!loaded[k] || k == m) continue;
            value[k] = ++*counter * 0.25;
            other[k] = *counter % 1000;
            CHECK(st_world_set_param(w, probes[k], "value", value[k], &err), "%s", err.msg);
            CHECK(st_world_set_param(w, probes[k], "other", other[k], &err), "%s", err.msg);
        }
        float px[3];
        if (!frame_pixel(w, px)) break;
        for (int k = 0; k < 3; k++) {
            double got[2] = {-1, -1}, param = -1;
            CHECK(st_world_has_module(w, probes[k]) == loaded[k], "step %d: %s loaded", step,
                  probes[k]);
            CHECK_REL(px[k], loaded[k] ? value[k] : 0.0, 0, 1e-6);
            if (!loaded[k]) continue;
            CHECK(seen[k](got), "%s has a live instance", probes[k]);
            CHECK(got[0] == value[k] && got[1] == other[k],
                  "step %d: %s reads (%g, %g), set (%g, %g)", step, probes[k], got[0], got[1],
                  value[k], other[k]);
            CHECK(st_world_get_param(w, probes[k], "value", &param) && param == value[k],
                  "%s get_param %g", probes[k], param);
        }
        // probe_c orders after probe_a whenever both are loaded.
        int ia = -1, ic = -1;
        for (int i = 0; i < st_world_num_modules(w); i++) {
            const char *nm = st_world_module(w, i).plugin->name;
            if (!strcmp(nm, "probe_a")) ia = i;
            if (!strcmp(nm, "probe_c")) ic = i;
        }
        if (ia >= 0 && ic >= 0) CHECK(ia < ic, "probe_a (%d) before probe_c (%d)", ia, ic);
    }
    st_world_destroy(w);
}

static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

static void part_probes(void) {
    void *handles[3] = {0};
    for (int k = 0; k < 3; k++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.so", ST_TEST_PROBE_DIR, probes[k]);
        void *h = handles[k] =
            dlopen(path, RTLD_NOW | RTLD_LOCAL); // the world's handle is the same
        CHECK(h != NULL, "dlopen %s: %s", path, dlerror());
        if (!h) return;
        *(void **)&seen[k] = dlsym(h, "probe_seen");
        CHECK(seen[k] != NULL, "probe_seen in %s", path);
        if (!seen[k]) return;
    }
    st_scene sc = {0};
    st_err err = {0};
    CHECK(
        st_scene_parse(probe_scene, strlen(probe_scene), ST_TEST_SCRATCH "/probe.json", &sc, &err),
        "%s", err.msg);
    int counter = 0;
    for (int a = 0; a < 6; a++)
        for (int b = 0; b < 6; b++)
            probe_sequence(&sc, perms[a], perms[b], &counter);
    st_scene_free(&sc);
    for (int k = 0; k < 3; k++)
        dlclose(handles[k]);
}

// ---- part 2: the real plugins ---------------------------------------------

static const char *real_base = "\"image\": {\"width\": 48, \"height\": 48},\n"
                               " \"camera\": {\"position\": [0.5, 1.7, 7], \"target\": [0, 1.5, "
                               "0], \"up\": [0, 1, 0], \"fov_y\": 50,"
                               " \"near\": 0.05, \"far\": 40},\n"
                               " \"lights\": [{\"type\": \"point\", \"position\": [0.2, 1.8, 2.2], "
                               "\"intensity\": [12, 12, 12]}],\n"
                               " \"geometry\": [\n"
                               "  {\"quad\": {\"corner\": [-8, 0, -8], \"u\": [0, 0, 16], \"v\": "
                               "[16, 0, 0]}, \"albedo\": [0.5, 0.5, 0.5]},\n"
                               "  {\"quad\": {\"corner\": [-8, 0, -4], \"u\": [16, 0, 0], \"v\": "
                               "[0, 6, 0]}, \"albedo\": [0.6, 0.6, 0.6]},\n"
                               "  {\"box\": {\"min\": [-0.6, 0, -0.2], \"max\": [-0.2, 3.2, 0.2]}, "
                               "\"albedo\": [0.6, 0.55, 0.5]},\n"
                               "  {\"box\": {\"min\": [0.4, 0, 1.0], \"max\": [0.8, 3.2, 1.4]}, "
                               "\"albedo\": [0.6, 0.55, 0.5]}],\n"
                               " \"medium\": {\"sigma_s\": [0.08, 0.08, 0.08], \"sigma_a\": [0.01, "
                               "0.01, 0.01], \"phase\": {\"hg\": 0.3}}";

// Parameters the test changes, cycling through their values.
static const struct {
    const char *module, *param;
    double v[3];
} tweaks[] = {
    {"shadow_map", "bias", {2, 0.5, 4}},
    {"shadow_map", "pcf", {1, 0, 1}},
    {"ssgi", "samples", {16, 9, 25}},
    {"ssgi", "min_cos", {0.25, 0.5, 0.125}},
    {"mitchell", "n", {24, 40, 17}},
    {"mitchell", "exposure", {0.5, 0.25, 0.75}},
    {"mitchell", "decay", {0.96875, 0.9375, 1}},
    {"sousa", "taps", {4, 8, 3}},
    {"sousa", "brightness", {0.5, 0.75, 0.25}},
    {"mitchell", "resolution", {0.5, 0.25, 1}},
    {"sousa", "resolution", {0.5, 1, 0.25}},
};
#define NUM_TWEAKS (int)(sizeof tweaks / sizeof tweaks[0])

static bool render(st_world *w, st_image *img) {
    st_err err = {0};
    bool ok = st_world_frame(w, &err) && st_world_frame(w, &err) && st_world_read(w, img, &err);
    CHECK(ok, "frame: %s", err.msg);
    return ok;
}

// The image of a world created from scratch with w's modules, order and parameters.
static bool fresh_image(st_world *w, st_image *img) {
    static char json[16384];
    int n = snprintf(json, sizeof json, "{%s,\n \"modules\": [", real_base);
    for (int i = 0; i < st_world_num_modules(w); i++) {
        st_module_info mi = st_world_module(w, i);
        n += snprintf(json + n, sizeof json - n, "%s{\"name\": \"%s\", \"params\": {",
                      i ? ", " : "", mi.plugin->name);
        for (int k = 0; k < mi.plugin->num_params; k++) {
            const st_param_def *d = &mi.plugin->params[k];
            char v[64];
            st_param_format(d, mi.params[k], v, sizeof v);
            bool quote = d->type == ST_PARAM_ENUM;
            n += snprintf(json + n, sizeof json - n, "%s\"%s\": %s%s%s", k ? ", " : "", d->name,
                          quote ? "\"" : "", v, quote ? "\"" : "");
        }
        n += snprintf(json + n, sizeof json - n, "}}");
    }
    snprintf(json + n, sizeof json - n, "]}\n");
    st_scene sc = {0};
    st_err err = {0};
    bool ok = st_scene_parse(json, strlen(json), ST_TEST_SCRATCH "/fresh.json", &sc, &err);
    CHECK(ok, "fresh scene: %s", err.msg);
    st_world *f = ok ? st_world_create(&sc, NULL, &err) : NULL;
    CHECK(!ok || f, "fresh world: %s", err.msg);
    ok = f && render(f, img);
    st_world_destroy(f);
    st_scene_free(&sc);
    return ok;
}

static void real_sequence(const st_scene *sc, const char *const *steps, int nsteps) {
    st_err err = {0};
    st_world *w = st_world_create(sc, NULL, &err);
    CHECK(w != NULL, "world: %s", err.msg);
    if (!w) return;
    size_t bytes0 = st_gpu_bytes(); // the world's own targets and buffers
    for (int s = 0; s < nsteps; s++) {
        const char *m = steps[s] + 1;
        bool on = steps[s][0] == '+';
        CHECK(st_world_enable(w, m, on, &err), "%s: %s", steps[s], err.msg);
        // Change the parameters of every loaded module.
        for (int t = 0; t < NUM_TWEAKS; t++) {
            if (!st_world_has_module(w, tweaks[t].module)) continue;
            double v = tweaks[t].v[s % 3], got = -1;
            CHECK(st_world_set_param(w, tweaks[t].module, tweaks[t].param, v, &err), "%s", err.msg);
            CHECK(st_world_get_param(w, tweaks[t].module, tweaks[t].param, &got) && got == v,
                  "%s.%s = %g, set %g", tweaks[t].module, tweaks[t].param, got, v);
        }
        st_image a = {0}, b = {0};
        if (render(w, &a) && fresh_image(w, &b)) {
            double maxd = 0, maxv = 0;
            for (size_t i = 0; i < (size_t)a.width * a.height * 3; i++) {
                double d = fabs(a.data[i] - b.data[i]);
                if (d > maxd || !(d == d)) maxd = d;
                if (fabs(b.data[i]) > maxv) maxv = fabs(b.data[i]);
            }
            printf("after %-12s %d modules: max |switched - fresh| %.3g (image max %.3g)\n",
                   steps[s], st_world_num_modules(w), maxd, maxv);
            CHECK(maxv > 0, "image not black");
            CHECK(maxd <= 1e-5 * maxv, "after %s: switched world differs from a fresh one by %g",
                  steps[s], maxd);
        }
        st_image_free(&a);
        st_image_free(&b);
    }
    // Switched off, a module leaves no GPU memory behind (its targets are
    // the world's and go with it).
    while (st_world_num_modules(w) > 0) {
        const char *m = st_world_module(w, st_world_num_modules(w) - 1).plugin->name;
        CHECK(st_world_enable(w, m, false, &err), "off %s: %s", m, err.msg);
    }
    CHECK(st_gpu_bytes() == bytes0, "GPU bytes after every module is off: %zu, before: %zu",
          st_gpu_bytes(), bytes0);
    st_world_destroy(w);
}

static void part_real(void) {
    static char json[8192];
    snprintf(json, sizeof json, "{%s, \"modules\": []}\n", real_base);
    st_scene sc = {0};
    st_err err = {0};
    CHECK(st_scene_parse(json, strlen(json), ST_TEST_SCRATCH "/real.json", &sc, &err), "%s",
          err.msg);
    static const char *forward[] = {"+shadow_map", "+mitchell",   "+sousa",    "+ssgi",
                                    "-mitchell",   "-shadow_map", "+mitchell", "-sousa",
                                    "+shadow_map", "-ssgi"};
    static const char *backward[] = {"+ssgi",  "+sousa", "+mitchell", "-ssgi",      "+shadow_map",
                                     "-sousa", "+ssgi",  "-mitchell", "-shadow_map"};
    real_sequence(&sc, forward, (int)(sizeof forward / sizeof forward[0]));
    real_sequence(&sc, backward, (int)(sizeof backward / sizeof backward[0]));
    st_scene_free(&sc);
}

int main(void) {
    // The probes live in their own folder, searched first.
    char path[4096];
    const char *old = getenv("STRAHL_MODULE_PATH");
    snprintf(path, sizeof path, "%s%s%s", ST_TEST_PROBE_DIR, old ? ":" : "", old ? old : "");
    setenv("STRAHL_MODULE_PATH", path, 1);
    st_context *ctx = st_test_context();
    part_probes();
    part_real();
    st_context_destroy(ctx);
    return st_test_summary("test_module_switch");
}
