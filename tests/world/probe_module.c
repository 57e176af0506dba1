// A test plugin, built three times under different names (probe_a, probe_b,
// probe_c): one post pass adds its parameter "value" to one channel of the
// image, read through the pointer create() received. probe_seen() reports
// that value to the test, which dlopens the same file (same handle) to ask.
// Built a fourth time as probe_old with PROBE_OLD_ABI: a descriptor as ABI
// 1.2 had it (test_declared_passes loads it into this 1.3 strahl).
#include "st_module.h"
#include <stddef.h>
#include <stdlib.h>

static const st_param_def params[] = {
    {"value", ST_PARAM_FLOAT, 0, -1000, 1000, NULL, "added to channel PROBE_CHANNEL"},
    {"other", ST_PARAM_INT, 7, 0, 1000, NULL, "only read back"},
};

typedef struct probe {
    const double *p;
    GLuint prog;
    st_pass_info info;
} probe;

static probe *live; // the current instance (at most one per process in the test)

static const char *vs = "#version 450\n"
                        "void main() { vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);\n"
                        "  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0); }\n";
static const char *fs =
    "#version 450\n"
    "layout(binding = 0) uniform sampler2D src; uniform vec3 add; out vec4 o;\n"
    "void main() { o = texelFetch(src, ivec2(gl_FragCoord.xy), 0) + vec4(add, 0.0); }\n";

static void *create(st_world *w, const double *p, st_err *err) {
    probe *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->p = p;
    s->prog = st_program_from_source(vs, fs, PROBE_NAME, err);
    if (!s->prog) {
        free(s);
        return NULL;
    }
    s->info = (st_pass_info){"add", ST_STAGE_POST, "hdr", "hdr", 0};
    live = s;
    return s;
}

static void destroy(void *self) {
    probe *s = self;
    glDeleteProgram(s->prog);
    if (live == s) live = NULL;
    free(s);
}

static int num_passes(void *self) {
    return 1;
}
static const st_pass_info *pass_info(void *self, int pass) {
    return &((probe *)self)->info;
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    probe *s = self;
    float add[3] = {0, 0, 0};
    add[PROBE_CHANNEL] = (float)s->p[0];
    glUseProgram(s->prog);
    glUniform3fv(glGetUniformLocation(s->prog, "add"), 1, add);
    glBindTextureUnit(0, f->hdr_in);
    st_draw_fullscreen();
    return st_gl_check(PROBE_NAME, err);
}

#ifndef PROBE_OLD_ABI
ST_PLUGIN(.name = PROBE_NAME, .description = "test plugin: adds its parameter to one channel",
          ST_PARAMS(params), .requires = PROBE_REQUIRES, .provides = PROBE_NAME, .create = create,
          .destroy = destroy, .num_passes = num_passes, .pass_info = pass_info, .on_pass = on_pass)
#else
// As a plugin built against ABI 1.2 would be: minor 2, st_plugin, st_frame
// and the size table as long as they were before 1.3 appended to them. The
// 1.3 fields hold garbage, which the loader must never read (it copies
// struct_size bytes).
static const st_plugin old_desc = {.abi_major = ST_ABI_MAJOR,
                                   .abi_minor = 2,
                                   .struct_size = offsetof(st_plugin, passes),
                                   .name = PROBE_NAME,
                                   .description = "test plugin built as ABI 1.2",
                                   ST_PARAMS(params),
                                   .requires = PROBE_REQUIRES,
                                   .provides = PROBE_NAME,
                                   .create = create,
                                   .destroy = destroy,
                                   .num_passes = num_passes,
                                   .pass_info = pass_info,
                                   .on_pass = on_pass,
                                   .passes = (const st_pass_decl *)16,
                                   .num_pass_decls = 1000,
                                   .param_uniforms = (const char *)8};
ST_EXPORT const st_plugin *strahl_plugin(void) {
    return &old_desc;
}
ST_EXPORT const st_abi_sizes *strahl_plugin_sizes(void) {
    static st_abi_sizes s = ST_ABI_SIZES;
    s.struct_size = offsetof(st_abi_sizes, pass_decl);
    s.plugin = offsetof(st_plugin, passes);
    s.frame = offsetof(st_frame, shader);
    return &s;
}
#endif

// What the live instance reads through its parameter pointer; false if none.
ST_EXPORT bool probe_seen(double out[2]) {
    if (!live) return false;
    out[0] = live->p[0];
    out[1] = live->p[1];
    return true;
}
