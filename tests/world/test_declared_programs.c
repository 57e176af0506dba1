// Declared programs, compute passes, exports and world-owned buffers (ABI
// 1.4). probe_abi (see probe_abi.c) fills two array targets with compute
// passes, g(x, y, l) = x + 32 y + 512 l + 4096 MODE + 32768 VALUE + data[l],
// MODE and VALUE compiled in from its parameters, and its post pass adds
// (grid(x, y, 2), cells(x, y, 1), data[cells - 1] (+ 0.5 with alt)) to a
// black image; probe_reader, another module, adds (grid(x, y, 0), 0,
// value + 10 mode + 100 alt) from probe_abi's exports. The test checks every
// texel and pixel, the invocation counts of the dispatches, the recompiles
// on a parameter change (and the refusal of a value that does not compile),
// the program hook, the buffers' contents, sizes and lifetimes, hot reload,
// and that the programs are deleted with the module. probe_decl13 is
// probe_decl as ABI 1.3 built it (shorter pass rows); probe_bad's broken
// tables must be refused, each with its message.
#include "probe_world.h"
#include "st_world_state.h"

enum { W = 20, H = 12 };

// The compute program of both compute passes; `extra` is baked into g.
static bool write_fill(double extra) {
    char text[2048];
    snprintf(text, sizeof text,
             "layout(local_size_x = 8, local_size_y = 8) in;\n"
             "layout(r32f, binding = 0) uniform writeonly image2DArray o_img;\n"
             "layout(std430, binding = 1) buffer Count { uint n[4]; };\n"
             "layout(std430, binding = 2) readonly buffer Data { float d[]; };\n"
             "#if PROBE_ABI_MODE == 7\n#error mode 7 does not compile\n#endif\n"
             "float g(ivec2 q, int l) {\n"
             "  float dl = l < d.length() ? d[l] : 0.0;\n"
             "  return float(q.x + 32 * q.y + 512 * l + 4096 * PROBE_ABI_MODE) +\n"
             "         32768.0 * float(PROBE_ABI_VALUE) + dl + %.2f;\n}\n"
             "void main() {\n  ivec3 p = ivec3(gl_GlobalInvocationID), size = imageSize(o_img);\n"
             "  atomicAdd(n[PLANE == 1 ? 0 : 1], 1u);\n"
             "  if (p.x >= size.x || p.y >= size.y) return;\n"
             "#if PLANE\n  for (int l = 0; l < size.z; l++) {\n"
             "    imageStore(o_img, ivec3(p.xy, l), vec4(g(p.xy, l)));\n"
             "    atomicAdd(n[2], 1u);\n  }\n"
             "#else\n  if (p.z >= size.z) return;\n"
             "  imageStore(o_img, p, vec4(g(p.xy, p.z)));\n  atomicAdd(n[3], 1u);\n#endif\n}\n",
             extra);
    return write_file("probe_abi", "fill.comp", text);
}

static bool write_shaders(void) {
    return write_fill(0) &&
           write_file("probe_abi", "zero.comp",
                      "layout(local_size_x = 1) in;\n"
                      "layout(std430, binding = 1) buffer Count { uint n[4]; };\n"
                      "void main() { n[0] = 0u; n[1] = 0u; n[2] = 0u; n[3] = 0u; }\n") &&
           write_file(
               "probe_abi", "show.frag",
               "uniform sampler2D st_hdr_in;\nuniform sampler2DArray u_abi_grid, u_cells;\n"
               "uniform samplerBuffer u_data;\nuniform int u_cells_n;\n"
               "layout(location = 0) out vec4 o;\n"
               "void main() {\n  ivec2 p = ivec2(gl_FragCoord.xy);\n"
               "  float b = texelFetch(u_data, u_cells_n - 1).r;\n"
               "#ifdef ALT\n  b += 0.5;\n#endif\n"
               "  o = texelFetch(st_hdr_in, p, 0) + vec4(texelFetch(u_abi_grid, "
               "ivec3(p, 2), 0).r,\n    texelFetch(u_cells, ivec3(p, 1), 0).r, b, 0.0);\n}\n") &&
           write_file("probe_reader", "read.frag",
                      "uniform sampler2D st_hdr_in;\nuniform sampler2DArray u_abi_grid;\n"
                      "uniform float u_abi_value;\nuniform int u_abi_mode;\n"
                      "uniform bool u_abi_alt;\nlayout(location = 0) out vec4 o;\n"
                      "void main() {\n  ivec2 p = ivec2(gl_FragCoord.xy);\n"
                      "  o = texelFetch(st_hdr_in, p, 0) + vec4(texelFetch(u_abi_grid, "
                      "ivec3(p, 0), 0).r, 0.0,\n"
                      "    u_abi_value + 10.0 * float(u_abi_mode) + (u_abi_alt ? 100.0 : 0.0), "
                      "0.0);\n}\n") &&
           write_file("probe_hook", "count.comp",
                      "layout(local_size_x = 8, local_size_y = 8) in;\n"
                      "layout(r32f, binding = 0) uniform writeonly image2D o;\n"
                      "layout(std430, binding = 1) buffer Count { uint n; };\n"
                      "void main() {\n  atomicAdd(n, 1u);\n"
                      "  imageStore(o, ivec2(gl_GlobalInvocationID.xy), vec4(1.0));\n}\n") &&
           write_file("probe_bad", "p.comp",
                      "layout(local_size_x = 1) in;\nlayout(r32f) uniform writeonly image2D o;\n"
                      "void main() { imageStore(o, ivec2(gl_GlobalInvocationID.xy), vec4(1)); "
                      "}\n");
}

// What the probe's parameters make: g and the post pass's blue.
typedef struct expect {
    double value, extra;
    int mode, cells;
    bool alt, reader;
} expect;

static double g(const expect *e, int x, int y, int l) {
    double d = l < e->cells ? 0.25 * (l + 1) : 0;
    return x + 32 * y + 512 * l + 4096 * e->mode + 32768 * e->value + d + e->extra;
}

static double blue(const expect *e) {
    double b = 0.25 * e->cells + (e->alt ? 0.5 : 0);
    return b + (e->reader ? e->value + 10 * e->mode + (e->alt ? 100 : 0) : 0);
}

// The largest difference of any pixel from what `e` says (1e30: no image).
static double image_error(st_world *w, const expect *e) {
    st_image img = {0};
    if (!frame_image(w, &img)) return 1e30;
    double worst = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const float *px = st_image_px(&img, x, y);
            int gy = H - 1 - y; // the image's rows run top-down, GL's bottom-up
            double want[3] = {g(e, x, gy, 2) + (e->reader ? g(e, x, gy, 0) : 0), g(e, x, gy, 1),
                              blue(e)};
            for (int c = 0; c < 3; c++)
                if (!(fabs(px[c] - want[c]) <= worst)) worst = fabs(px[c] - want[c]);
        }
    st_image_free(&img);
    return worst;
}

// The largest difference of any texel of array target `name` from g.
static double target_error(st_world *w, const char *name, int layers, const expect *e) {
    const st_target *t = st_world_target(w, name);
    if (!t || t->width != W || t->height != H || t->layers != layers) return 1e30;
    static float texels[W * H * 3];
    glGetTextureImage(t->color[0], 0, GL_RED, GL_FLOAT, (GLsizei)sizeof texels, texels);
    double worst = 0;
    for (int l = 0; l < layers; l++)
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                double d = fabs(texels[(l * H + y) * W + x] - g(e, x, y, l));
                if (!(d <= worst)) worst = d;
            }
    return worst;
}

// A world-owned object's GL name and bytes (0 when there is none).
static GLuint object(st_world *w, const char *name, size_t *bytes) {
    for (int i = 0; i < w->targets.nk; i++)
        if (!strcmp(w->targets.k[i].name, name)) {
            if (bytes) *bytes = w->targets.k[i].bytes;
            return w->targets.k[i].obj;
        }
    return 0;
}

static int memory_rows(st_world *w, const char *owner) {
    st_mem_entry rows[64];
    int n = st_world_memory(w, rows, 64), k = 0;
    for (int i = 0; i < n && i < 64; i++)
        k += !strcmp(rows[i].owner, owner);
    return k;
}

// The GL names of a module's declared programs compiled so far.
static int programs_of(st_world *w, const char *module, GLuint *out, int max) {
    int n = 0;
    for (int m = 0; m < w->num_mods; m++) {
        const st_module_inst *mi = w->mods[m];
        if (strcmp(mi->p->name, module) || !mi->progs) continue;
        for (int k = 0; k < mi->p->num_programs && n < max; k++)
            if (mi->progs[k]) out[n++] = mi->progs[k]->program;
    }
    return n;
}

static bool set(st_world *w, const char *module, const char *param, double v) {
    st_err err = {0};
    bool ok = st_world_set_param(w, module, param, v, &err);
    CHECK(ok, "%s.%s = %g: %s", module, param, v, err.msg);
    return ok;
}

// The compute passes: every texel, every pixel, the invocation counts.
static void part_compute(st_world *w, const expect *e) {
    double err_img = image_error(w, e);
    CHECK(err_img == 0, "every pixel (grid layer 2, cells layer 1, data[3] = 1): max error %g",
          err_img);
    double eg = target_error(w, "probe_abi.grid", 3, e),
           ec = target_error(w, "probe_abi.cells", 2, e);
    CHECK(eg == 0 && ec == 0, "every texel of grid (3 layers) and cells (2 layers) is g: %g %g", eg,
          ec);
    GLuint n[4] = {0};
    GLuint count = object(w, "probe_abi.count", NULL);
    if (count) glGetNamedBufferSubData(count, 0, sizeof n, n);
    // 20 x 12 texels in 8 x 8 groups: 3 x 2 groups of 64 = 384 invocations.
    CHECK(n[0] == 384 && n[2] == 720,
          "ST_PASS_PLANE: 384 invocations (20x12 in 8x8 groups, not x3 layers), 720 texels "
          "written by the program's own loop: %u %u",
          n[0], n[2]);
    CHECK(n[1] == 768 && n[3] == 480,
          "per layer: 768 invocations (384 x 2 layers), 480 texels written: %u %u", n[1], n[3]);
    const st_pass_stats *grid = stats(w, "probe_abi", "grid"),
                        *cells = stats(w, "probe_abi", "cells");
    CHECK(grid && cells && grid->ran_last_frame && cells->ran_last_frame,
          "both compute passes ran");
}

// param_defines: a recompile per change, and a value that does not compile.
static void part_defines(st_world *w, expect *e) {
    int programs = live_programs();
    set(w, "probe_abi", "value", 3);
    e->value = 3;
    double d = image_error(w, e);
    CHECK(d == 0, "value 3 compiled in (32768 x 3 in every texel): max error %g", d);
    CHECK(live_programs() == programs,
          "fill and layers recompiled, the old ones deleted: %d, was %d", live_programs(),
          programs);
    st_err err = {0};
    bool ok = st_world_set_param(w, "probe_abi", "mode", 7, &err);
    CHECK(!ok && strstr(err.msg, "probe_abi/fill.comp") && strstr(err.msg, "probe_abi.mode"),
          "mode 7 (#error) refused, naming the file and the parameter: %s", err.msg);
    double mode = -1;
    st_world_get_param(w, "probe_abi", "mode", &mode);
    CHECK(mode == 1, "mode stays 1: %g", mode);
    d = image_error(w, e);
    CHECK(d == 0, "the images still show mode 1: max error %g", d);
    CHECK(live_programs() == programs, "the failed compile left no program: %d, was %d",
          live_programs(), programs);
    set(w, "probe_abi", "mode", 2);
    e->mode = 2;
    d = image_error(w, e);
    CHECK(d == 0, "mode 2 compiled in (4096 x 2): max error %g", d);
}

// The program hook: show_alt (compiled on first use), then the pass drawn by
// the plugin itself with st_frame_use_program.
static void part_hook(st_world *w, expect *e) {
    int programs = live_programs();
    set(w, "probe_abi", "alt", 1);
    e->alt = true;
    double d = image_error(w, e);
    CHECK(d == 0, "alt: the hook picks show_alt (blue 1 + 0.5): max error %g", d);
    CHECK(live_programs() == programs + 1, "show_alt compiled on first use: %d, was %d",
          live_programs(), programs);
    set(w, "probe_abi", "self", 1);
    d = image_error(w, e);
    const st_pass_stats *show = stats(w, "probe_abi", "show");
    CHECK(d == 0 && show && show->ran_last_frame,
          "hook -1, on_pass draws show_alt itself: the same image, max error %g", d);
    set(w, "probe_abi", "self", 0);
}

// Exports read by another module: parameters as float, int and bool, and a target.
static void part_exports(st_world *w, expect *e) {
    st_err err = {0};
    CHECK(st_world_enable(w, "probe_reader", true, &err), "probe_reader loads: %s", err.msg);
    e->reader = true;
    double d = image_error(w, e);
    CHECK(d == 0,
          "probe_reader adds grid layer 0 (exported target) and value 3 + 10 x mode 2 + 100 x "
          "alt (float, int, bool exports): max error %g",
          d);
    set(w, "probe_abi", "value", 4);
    e->value = 4;
    d = image_error(w, e);
    CHECK(d == 0, "value 4 reaches the other module's uniform: max error %g", d);
    CHECK(st_world_enable(w, "probe_reader", false, &err), "probe_reader off: %s", err.msg);
    e->reader = false;
}

// World-owned buffers: contents, a new buffer (and buffer texture) when the
// size changes.
static void part_buffers(st_world *w, expect *e) {
    size_t bytes = 0;
    GLuint data = object(w, "probe_abi.data", &bytes), tex = object(w, "probe_abi.data_tex", NULL);
    float got[6] = {0};
    if (data) glGetNamedBufferSubData(data, 0, 4 * sizeof(float), got);
    CHECK(data && bytes == 16 && got[0] == 0.25f && got[3] == 1.0f,
          "data: 4 floats, 16 bytes, 0.25 .. 1: %zu bytes, %g .. %g", bytes, got[0], got[3]);
    CHECK(tex && glIsTexture(tex), "the buffer texture over it");
    set(w, "probe_abi", "cells", 6);
    e->cells = 6;
    double d = image_error(w, e);
    CHECK(d == 0, "cells 6: blue reads data[5] = 1.5 through the buffer texture: max error %g", d);
    GLuint data2 = object(w, "probe_abi.data", &bytes),
           tex2 = object(w, "probe_abi.data_tex", NULL);
    if (data2) glGetNamedBufferSubData(data2, 0, 6 * sizeof(float), got);
    CHECK(data2 && data2 != data && !glIsBuffer(data) && bytes == 24 && got[5] == 1.5f,
          "re-created at 24 bytes (GL name %u -> %u, the old one deleted), data[5] %g", data, data2,
          got[5]);
    CHECK(tex2 && tex2 != tex && !glIsTexture(tex), "a new buffer texture, the old one deleted");
}

// Hot reload of a declared compute program: its parameter defines stay; a
// broken file keeps the old program.
static void part_reload(st_world *w, expect *e) {
    st_err err = {0};
    CHECK(write_fill(0.5), "rewrite fill.comp");
    CHECK(st_world_reload_shaders(w, &err), "reload: %s", err.msg);
    e->extra = 0.5;
    double d = image_error(w, e);
    CHECK(d == 0, "reloaded: +0.5 in every texel, value 4 and mode 2 still compiled in: %g", d);
    CHECK(write_file("probe_abi", "fill.comp", "this is not GLSL\n"), "break fill.comp");
    CHECK(!st_world_reload_shaders(w, &err) && strstr(err.msg, "probe_abi/fill.comp"),
          "a broken file fails the reload naming it: %s", err.msg);
    d = image_error(w, e);
    CHECK(d == 0, "the old program stays: max error %g", d);
    CHECK(write_fill(0), "restore fill.comp");
}

static void part_probe(st_world *w) {
    st_err err = {0};
    int programs = live_programs();
    CHECK(st_world_enable(w, "probe_abi", true, &err), "probe_abi loads: %s", err.msg);
    CHECK(live_programs() == programs + 4,
          "the world compiled fill, layers, show (the rows') and zero (st_world_program): %d, "
          "was %d",
          live_programs(), programs);
    expect e = {.value = 2, .mode = 1, .cells = 4};
    part_compute(w, &e);
    part_defines(w, &e);
    part_hook(w, &e);
    part_exports(w, &e);
    part_buffers(w, &e);
    part_reload(w, &e);
    GLuint data = object(w, "probe_abi.data", NULL), count = object(w, "probe_abi.count", NULL),
           tex = object(w, "probe_abi.data_tex", NULL);
    GLuint names[8];
    int n = programs_of(w, "probe_abi", names, 8);
    CHECK(st_world_enable(w, "probe_abi", false, &err), "probe_abi off: %s", err.msg);
    st_image img = {0};
    // A frame first, as in test_declared_passes: Mesa frees a deleted program
    // once no stage of it is bound. (The world's regular program, rebuilt
    // without the module, is not counted: with no geometry in the scene the
    // old one's geometry stage stays bound.)
    frame_image(w, &img);
    st_image_free(&img);
    int alive = 0;
    for (int k = 0; k < n; k++)
        alive += glIsProgram(names[k]) == GL_TRUE;
    CHECK(n == 5 && alive == 0, "its 5 programs are deleted: %d of %d alive", alive, n);
    CHECK(memory_rows(w, "probe_abi") == 0 && !glIsBuffer(data) && !glIsBuffer(count) &&
              !glIsTexture(tex),
          "its targets, buffers and buffer texture are gone (%d rows)",
          memory_rows(w, "probe_abi"));
}

// A buffer the plugin made and tracks stays the plugin's, wherever in the
// registry it lands (a slot an owned buffer used before included).
static void part_tracking(st_world *w) {
    st_err err = {0};
    GLuint a = st_world_buffer(w, "probe_t.a", 16, NULL, &err);
    GLuint b = st_world_buffer(w, "probe_t.b", 16, NULL, &err);
    CHECK(a && b, "two world-owned buffers: %s", err.msg);
    st_world_untrack(w, "probe_t.a");
    CHECK(!glIsBuffer(a), "untracking a world-owned buffer deletes it");
    GLuint mine = 0;
    glCreateBuffers(1, &mine);
    glNamedBufferStorage(mine, 16, NULL, 0);
    CHECK(st_world_track(w, "probe_t.mine", GL_BUFFER, mine, &err), "track: %s", err.msg);
    st_world_untrack(w, "probe_t.mine");
    CHECK(glIsBuffer(mine), "untracking the plugin's own buffer leaves it alive");
    st_world_untrack(w, "probe_t.b");
    CHECK(!glIsBuffer(b), "the other world-owned buffer deleted");
    glDeleteBuffers(1, &mine);
}

// probe_decl as ABI 1.3 built it (`name`: probe_decl13 with its size table,
// probe_decl13h without): rows of the shorter st_pass_decl, garbage in the
// 1.4 fields past its struct_size. It renders what test_declared_passes
// asserts for probe_decl (value 3 as u_value, fill1 = 100 + 3).
static void part_old13(st_world *w, const char *name) {
    st_err err = {0};
    char what[64];
    CHECK(st_world_enable(w, name, true, &err), "%s, built as ABI 1.3, loads: %s", name, err.msg);
    const st_plugin *p = st_world_num_modules(w) == 1 ? st_world_module(w, 0).plugin : NULL;
    snprintf(what, sizeof what, "%s/add.frag", name);
    CHECK(p && p->abi_minor == 3 && p->num_pass_decls == 2 && !p->programs && !p->num_programs &&
              !p->exports && !p->program && p->passes[1].frag && !strcmp(p->passes[1].frag, what) &&
              !p->passes[0].program && !p->passes[1].program,
          "%s: minor 3, its rows read with this strahl's layout, the 1.4 fields NULL", name);
    float px[3] = {0};
    pixel(w, px);
    CHECK(px[0] == 3.0f && px[1] == 103.0f, "%s: value 3 as u_value, fill1 = 103: got %g %g", name,
          px[0], px[1]);
    const st_pass_stats *f0 = stats(w, name, "fill[0]");
    CHECK(f0 && f0->culled_last_frame, "%s: fill[0] culled, as with probe_decl", name);
    snprintf(what, sizeof what, "%s.fill1", name);
    CHECK(target_width(w, what) == W, "%s: fill1 at the screen's 20 px: %d", name,
          target_width(w, what));
    set(w, name, "scale", 0.5);
    set(w, name, "value", 5);
    pixel(w, px);
    CHECK(target_width(w, what) == W / 2 && px[0] == 5.0f && px[1] == 105.0f,
          "%s: scale 0.5 (the row's scale_param): 10 px; value 5: %d, %g %g", name,
          target_width(w, what), px[0], px[1]);
    CHECK(st_world_enable(w, name, false, &err), "%s off: %s", name, err.msg);
}

// A plugin without tables whose shader hook answers a compute program it
// dispatches itself: dispatched once (384 invocations), not again by the world.
static void part_hook_compute(st_world *w) {
    st_err err = {0};
    CHECK(st_world_enable(w, "probe_hook", true, &err), "probe_hook loads: %s", err.msg);
    st_image img = {0};
    frame_image(w, &img);
    st_image_free(&img);
    GLuint n = 0, count = object(w, "probe_hook.count", NULL);
    if (count) glGetNamedBufferSubData(count, 0, sizeof n, &n);
    CHECK(n == 384, "its own dispatch only: 384 invocations (768 if the world dispatched too): %u",
          n);
    CHECK(st_world_enable(w, "probe_hook", false, &err), "probe_hook off: %s", err.msg);
}

// Broken ABI 1.4 tables are refused when the module loads, each with its message.
static void part_bad(st_world *w) {
    static const struct {
        const char *kind, *msg;
    } bad[] = {
        {"pass", "bad pass program (not in the program table)"},
        {"export", "bad export (each: a uniform, and one parameter or target)"},
        {"both", "bad program table (each: a unique name, and frag or comp)"},
        {"define", "bad program parameter define"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        st_err err = {0};
        setenv("PROBE_BAD", bad[i].kind, 1);
        bool ok = st_world_enable(w, "probe_bad", true, &err);
        CHECK(!ok && strstr(err.msg, "module 'probe_bad'") && strstr(err.msg, bad[i].msg),
              "%s: refused with '%s': %s", bad[i].kind, bad[i].msg, err.msg);
        CHECK(st_world_num_modules(w) == 0, "%s: nothing loaded", bad[i].kind);
    }
    unsetenv("PROBE_BAD");
    st_err err = {0};
    CHECK(st_world_enable(w, "probe_bad", true, &err), "the valid tables load: %s", err.msg);
    CHECK(st_world_enable(w, "probe_bad", false, &err), "probe_bad off: %s", err.msg);
}

int main(void) {
    probe_dir_setup();
    CHECK(write_shaders() && write_decl("probe_decl13", false) &&
              write_decl("probe_decl13h", false),
          "write the probes' shaders");
    st_context *ctx = st_test_context();
    st_scene sc = {0};
    st_world *w = probe_world(W, H, ST_TEST_SCRATCH "/programs.json", &sc);
    if (w) {
        part_probe(w);
        part_tracking(w);
        part_hook_compute(w);
        part_old13(w, "probe_decl13");
        part_old13(w, "probe_decl13h");
        part_bad(w);
        st_world_destroy(w);
    }
    st_scene_free(&sc);
    st_context_destroy(ctx);
    return st_test_summary("test_declared_programs");
}
