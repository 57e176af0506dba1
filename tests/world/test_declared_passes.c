// Declared passes (ABI 1.3) and the plugins built before them. probe_decl
// declares a per-light pre-pass that fills its own target and a post pass
// that adds to the image; it loads no program and declares no target. The
// test checks that the world expands the table per light (and culls the
// light whose target nobody reads), sets the parameters as uniforms, sizes
// the targets by the `scale` parameter and resizes them when it changes,
// hot-reloads the programs from their files (keeping the old program when a
// file breaks) and deletes them with the module. probe_old is a plugin as
// ABI 1.2 built it (minor 2, shorter st_plugin and st_frame, garbage past
// its struct_size): it must load and run on the old path. ABI 1.4: an export
// of a world-owned buffer texture reaches the add pass, and a shader reload
// runs a pass again that waits for its inputs (ST_CHANGE_PROGRAMS).
#include "st_test_render.h"
#include "st_test_support.h"
#include "st_world.h"
#include <sys/stat.h>

static const char *scene_json =
    "{\"image\": {\"width\": 16, \"height\": 16},\n"
    " \"camera\": {\"position\": [0, 0, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0],"
    " \"fov_y\": 40, \"near\": 0.05, \"far\": 100},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1, 0], \"intensity\": [1, 1, 1]},\n"
    "            {\"type\": \"point\", \"position\": [1, 1, 0], \"intensity\": [1, 1, 1]}],\n"
    " \"geometry\": [], \"modules\": []}\n";

static bool write_file(const char *name, const char *text) {
    char path[4096];
    snprintf(path, sizeof path, "%s/shaders/probe_decl/%s", ST_TEST_PROBE_DIR, name);
    FILE *f = fopen(path, "w");
    if (!f) return false;
    fputs(text, f);
    return fclose(f) == 0;
}

// The post pass adds (u_value * gain, fill1, 0); `gain` is baked into the file.
static bool write_add(double gain) {
    char text[1024];
    snprintf(text, sizeof text,
             "uniform sampler2D st_hdr_in;\nuniform sampler2D u_fill;\nuniform float u_value;\n"
             "uniform samplerBuffer u_buf;\n"
             "layout(location = 0) out vec4 o;\n"
             "void main() {\n  ivec2 p = ivec2(gl_FragCoord.xy);\n"
             "  vec2 uv = (vec2(p) + 0.5) / vec2(textureSize(st_hdr_in, 0));\n"
             "  o = texelFetch(st_hdr_in, p, 0) + vec4(u_value * %.1f, texture(u_fill, uv).r, "
             "texelFetch(u_buf, 0).r, 0.0);\n}\n",
             gain);
    return write_file("add.frag", text);
}

static bool pixel(st_world *w, float out[3]) {
    st_err err = {0};
    st_image img = {0};
    bool ok = st_world_frame(w, &err) && st_world_read(w, &img, &err);
    CHECK(ok, "frame: %s", err.msg);
    if (ok) memcpy(out, st_image_px(&img, 8, 8), 3 * sizeof(float));
    st_image_free(&img);
    return ok;
}

static const st_pass_stats *stats(const st_world *w, const char *module, const char *pass) {
    for (int i = 0; i < st_world_num_pass_stats(w); i++) {
        const st_pass_stats *s = st_world_pass_stats(w, i);
        if (!strcmp(s->module, module) && !strcmp(s->pass, pass)) return s;
    }
    return NULL;
}

static int target_width(st_world *w, const char *name) {
    st_mem_entry rows[64];
    int n = st_world_memory(w, rows, 64);
    for (int i = 0; i < n && i < 64; i++)
        if (!strcmp(rows[i].name, name)) return rows[i].width;
    return -1;
}

// Programs alive in the context (a deleted program stays alive while it is
// the current one, so none is current while counting).
static int live_programs(void) {
    glUseProgram(0);
    int n = 0;
    for (GLuint i = 1; i < 4096; i++)
        n += glIsProgram(i) == GL_TRUE;
    return n;
}

static void part_declared(st_world *w) {
    st_err err = {0};
    int programs = live_programs();
    CHECK(st_world_enable(w, "probe_decl", true, &err), "probe_decl loads: %s", err.msg);
    CHECK(live_programs() == programs + 2, "the world loaded 2 programs (%d -> %d)", programs,
          live_programs());
    float px[3] = {0};
    pixel(w, px);
    CHECK(px[0] == 3.0f && px[1] == 103.0f, "value 3 as u_value, fill1 = 103: got %g %g", px[0],
          px[1]);
    CHECK(px[2] == 7.0f, "the exported buffer texture u_buf holds 7: got %g", px[2]);
    const st_pass_stats *f0 = stats(w, "probe_decl", "fill[0]"),
                        *f1 = stats(w, "probe_decl", "fill[1]"),
                        *add = stats(w, "probe_decl", "add");
    CHECK(f0 && f1 && add, "one fill pass per light and the add pass");
    if (f0 && f1 && add)
        CHECK(f0->culled_last_frame && f1->ran_last_frame && add->ran_last_frame,
              "fill[0] culled (nobody reads it), fill[1] and add ran");
    CHECK(target_width(w, "probe_decl.fill1") == 16, "fill1 at the screen's 16 px: %d",
          target_width(w, "probe_decl.fill1"));
    CHECK(st_world_set_param(w, "probe_decl", "scale", 0.5, &err) &&
              st_world_set_param(w, "probe_decl", "value", 5, &err),
          "set_param: %s", err.msg);
    pixel(w, px);
    CHECK(target_width(w, "probe_decl.fill1") == 8, "scale 0.5 resizes fill1 to 8 px: %d",
          target_width(w, "probe_decl.fill1"));
    CHECK(px[0] == 5.0f && px[1] == 105.0f, "value 5: got %g %g", px[0], px[1]);
    pixel(w, px);
    f1 = stats(w, "probe_decl", "fill[1]"); // the pass list was rebuilt by set_param
    CHECK(f1 && !f1->ran_last_frame && px[1] == 105.0f,
          "fill[1] waits while nothing changes, its target keeps 105: %g", px[1]);
    CHECK(write_add(2.0), "rewrite add.frag");
    CHECK(st_world_reload_shaders(w, &err), "reload: %s", err.msg);
    pixel(w, px);
    CHECK(px[0] == 10.0f, "hot reload: gain 2 gives 10, got %g", px[0]);
    f1 = stats(w, "probe_decl", "fill[1]");
    CHECK(f1 && f1->ran_last_frame, "a reload runs fill[1] again (ST_CHANGE_PROGRAMS)");
    CHECK(write_file("add.frag", "this is not GLSL\n"), "break add.frag");
    CHECK(!st_world_reload_shaders(w, &err) && strstr(err.msg, "add.frag"),
          "a broken file fails the reload naming it: %s", err.msg);
    pixel(w, px);
    CHECK(px[0] == 10.0f, "the old program stays: %g", px[0]);
    CHECK(write_add(1.0), "restore add.frag");
    CHECK(st_world_enable(w, "probe_decl", false, &err), "probe_decl off: %s", err.msg);
    // A frame first: Mesa frees a deleted program only once no stage of it
    // is bound any more, and the regular program (rebuilt without the
    // module) has a geometry stage that stays bound until the next draw.
    pixel(w, px);
    CHECK(live_programs() == programs, "its programs are deleted (%d, was %d)", live_programs(),
          programs);
    CHECK(target_width(w, "probe_decl.fill1") == -1, "its targets are gone");
}

static void part_old(st_world *w) {
    st_err err = {0};
    CHECK(st_world_enable(w, "probe_old", true, &err), "a plugin built as ABI 1.2 loads: %s",
          err.msg);
    int n = st_world_num_modules(w);
    CHECK(n == 1 && st_world_module(w, 0).plugin->abi_minor == 2 &&
              !st_world_module(w, 0).plugin->passes &&
              !st_world_module(w, 0).plugin->param_uniforms,
          "probe_old is minor 2, its 1.3 fields read as NULL");
    CHECK(st_world_set_param(w, "probe_old", "value", 7, &err), "set_param: %s", err.msg);
    float px[3] = {0};
    pixel(w, px);
    CHECK(px[0] == 7.0f && px[1] == 0.0f, "probe_old adds 7 to red: %g %g", px[0], px[1]);
    CHECK(st_world_enable(w, "probe_old", false, &err), "probe_old off: %s", err.msg);
}

int main(void) {
    char path[4096];
    const char *old = getenv("STRAHL_MODULE_PATH");
    snprintf(path, sizeof path, "%s%s%s", ST_TEST_PROBE_DIR, old ? ":" : "", old ? old : "");
    setenv("STRAHL_MODULE_PATH", path, 1);
    snprintf(path, sizeof path, "%s/shaders", ST_TEST_PROBE_DIR);
    mkdir(path, 0755);
    snprintf(path, sizeof path, "%s/shaders/probe_decl", ST_TEST_PROBE_DIR);
    mkdir(path, 0755);
    CHECK(write_add(1.0) && write_file("fill.frag", "uniform float u_value;\nuniform int u_k;\n"
                                                    "layout(location = 0) out float o;\n"
                                                    "void main() { o = u_value + 100.0 * "
                                                    "float(u_k); }\n"),
          "write the probe's shaders");
    st_context *ctx = st_test_context();
    st_scene sc = {0};
    st_err err = {0};
    bool parsed =
        st_scene_parse(scene_json, strlen(scene_json), ST_TEST_SCRATCH "/declared.json", &sc, &err);
    CHECK(parsed, "scene: %s", err.msg);
    st_world *w = parsed ? st_world_create(&sc, NULL, &err) : NULL;
    CHECK(w != NULL, "world: %s", err.msg);
    if (w) {
        part_declared(w);
        part_old(w);
        st_world_destroy(w);
    }
    st_scene_free(&sc);
    st_context_destroy(ctx);
    return st_test_summary("test_declared_passes");
}
