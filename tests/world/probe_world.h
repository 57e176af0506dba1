// What the tests that load probe plugins from the probe folder share
// (test_declared_passes, test_declared_programs): the module path, the
// probes' shader files, a world over a small scene with two lights, and what
// they read back from it. One copy, so both tests set up and measure alike.
#ifndef PROBE_WORLD_H
#define PROBE_WORLD_H
#include "st_test_render.h"
#include "st_test_support.h"
#include "st_world.h"
#include <sys/stat.h>

// The probe folder first on STRAHL_MODULE_PATH, and its shaders folder made.
static inline void probe_dir_setup(void) {
    char path[4096];
    const char *old = getenv("STRAHL_MODULE_PATH");
    snprintf(path, sizeof path, "%s%s%s", ST_TEST_PROBE_DIR, old ? ":" : "", old ? old : "");
    setenv("STRAHL_MODULE_PATH", path, 1);
    snprintf(path, sizeof path, "%s/shaders", ST_TEST_PROBE_DIR);
    mkdir(path, 0755);
}

// Writes <probe dir>/shaders/<dir>/<name> (making <dir>).
static inline bool write_file(const char *dir, const char *name, const char *text) {
    char path[4096];
    snprintf(path, sizeof path, "%s/shaders/%s", ST_TEST_PROBE_DIR, dir);
    mkdir(path, 0755);
    snprintf(path, sizeof path, "%s/shaders/%s/%s", ST_TEST_PROBE_DIR, dir, name);
    FILE *f = fopen(path, "w");
    if (!f) return false;
    fputs(text, f);
    return fclose(f) == 0;
}

// probe_decl's post pass (see probe_decl.c) adds (u_value * gain, fill1, b),
// b the exported buffer texture u_buf's first texel with `buf` (ABI 1.4's
// probe_decl exports it), else 0; `gain` is baked into the file.
static inline bool write_add(const char *dir, double gain, bool buf) {
    char text[1024];
    snprintf(text, sizeof text,
             "uniform sampler2D st_hdr_in;\nuniform sampler2D u_fill;\nuniform float u_value;\n"
             "%s"
             "layout(location = 0) out vec4 o;\n"
             "void main() {\n  ivec2 p = ivec2(gl_FragCoord.xy);\n"
             "  vec2 uv = (vec2(p) + 0.5) / vec2(textureSize(st_hdr_in, 0));\n"
             "  o = texelFetch(st_hdr_in, p, 0) + vec4(u_value * %.1f, texture(u_fill, uv).r, "
             "%s, 0.0);\n}\n",
             buf ? "uniform samplerBuffer u_buf;\n" : "", gain,
             buf ? "texelFetch(u_buf, 0).r" : "0.0");
    return write_file(dir, "add.frag", text);
}

// Both of probe_decl's programs into shaders/<dir>/, gain 1; its pre-pass
// fills light k's target with value + 100 k.
static inline bool write_decl(const char *dir, bool buf) {
    return write_add(dir, 1.0, buf) &&
           write_file(dir, "fill.frag",
                      "uniform float u_value;\nuniform int u_k;\n"
                      "layout(location = 0) out float o;\n"
                      "void main() { o = u_value + 100.0 * float(u_k); }\n");
}

// A world over a width x height image, two point lights, no geometry and no
// modules; `sc` holds the scene until st_scene_free. NULL when it fails.
static inline st_world *probe_world(int width, int height, const char *json_path, st_scene *sc) {
    char json[1024];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [0, 0, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0],"
             " \"fov_y\": 40, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 1, 0],"
             " \"intensity\": [1, 1, 1]},\n"
             "            {\"type\": \"point\", \"position\": [1, 1, 0],"
             " \"intensity\": [1, 1, 1]}],\n"
             " \"geometry\": [], \"modules\": []}\n",
             width, height);
    st_err err = {0};
    bool parsed = st_scene_parse(json, strlen(json), json_path, sc, &err);
    CHECK(parsed, "scene: %s", err.msg);
    st_world *w = parsed ? st_world_create(sc, NULL, &err) : NULL;
    CHECK(w != NULL, "world: %s", err.msg);
    return w;
}

static inline bool frame_image(st_world *w, st_image *img) {
    st_err err = {0};
    bool ok = st_world_frame(w, &err) && st_world_read(w, img, &err);
    CHECK(ok, "frame: %s", err.msg);
    return ok;
}

// A frame, and its pixel (8, 8).
static inline bool pixel(st_world *w, float out[3]) {
    st_image img = {0};
    bool ok = frame_image(w, &img);
    if (ok) memcpy(out, st_image_px(&img, 8, 8), 3 * sizeof(float));
    st_image_free(&img);
    return ok;
}

static inline const st_pass_stats *stats(const st_world *w, const char *module, const char *pass) {
    for (int i = 0; i < st_world_num_pass_stats(w); i++) {
        const st_pass_stats *s = st_world_pass_stats(w, i);
        if (!strcmp(s->module, module) && !strcmp(s->pass, pass)) return s;
    }
    return NULL;
}

// The width of target `name` (-1: there is none).
static inline int target_width(st_world *w, const char *name) {
    st_mem_entry rows[64];
    int n = st_world_memory(w, rows, 64);
    for (int i = 0; i < n && i < 64; i++)
        if (!strcmp(rows[i].name, name)) return rows[i].width;
    return -1;
}

// Programs alive in the context (a deleted program stays alive while it is
// the current one, so none is current while counting).
static inline int live_programs(void) {
    glUseProgram(0);
    int n = 0;
    for (GLuint i = 1; i < 4096; i++)
        n += glIsProgram(i) == GL_TRUE;
    return n;
}

#endif
