// A test plugin with declared passes (ABI 1.3), for test_declared_passes.
// Per light a pre-pass fills its own target "probe_decl.fill<k>" (R32F,
// `scale` of the screen) with value + 100 k; one post pass adds
// (value * GAIN, fill1, 0) to the image. Its programs are files in
// <probe dir>/shaders/probe_decl/, which the test writes and rewrites (hot
// reload). The plugin loads no program and declares no target itself.
// Built a second time as probe_decl13 with PROBE_OLD_ABI13: the same plugin
// as ABI 1.3 built it (minor 3, the shorter st_pass_decl rows, st_plugin,
// st_frame and the size table as long as they were before 1.4 appended to
// them; test_declared_programs loads it, its shaders in shaders/probe_decl13/),
// and a third time as probe_decl13h with PROBE_NO_SIZES: without the size
// table, so the loader knows the row size from the minor version alone.
// ABI 1.4: a world-owned buffer texture "probe_decl.values_tex" holding 7,
// exported as u_buf (the add pass puts it in blue); the fill passes run only
// on their first frame, a parameter change or a shader reload
// (ST_CHANGE_PROGRAMS), their target keeping its texels between.
#include "st_world_api.h"
#include <stddef.h>
#include <stdlib.h>

#ifndef PROBE_NAME
#define PROBE_NAME "probe_decl"
#endif

static const st_param_def params[] = {
    {"value", ST_PARAM_FLOAT, 3, -1000, 1000, NULL, "set as the uniform u_value"},
    {"scale", ST_PARAM_FLOAT, 1, 0.0625, 1, NULL, "size of the fill targets"},
};

#ifdef PROBE_OLD_ABI13
// st_pass_decl as ABI 1.3 had it (1.4 appended `program`).
typedef struct pass_decl13 {
    st_pass_info info;
    const char *vert, *frag;
    const char *defines;
    int count;
    st_target_desc target;
    const char *scale_param;
} pass_decl13;
static const pass_decl13 passes[] = {
#else
static const st_pass_decl passes[] = {
#endif
    {{"fill", ST_STAGE_PRE, "", PROBE_NAME ".fill%d", ST_PASS_FULLSCREEN},
     .frag = PROBE_NAME "/fill.frag",
     .count = ST_PER_LIGHT,
     .target = {GL_R32F, 1},
     .scale_param = "scale"},
    {{"add", ST_STAGE_POST, "hdr," PROBE_NAME ".fill1", "hdr", ST_PASS_FULLSCREEN},
     .frag = PROBE_NAME "/add.frag"},
};

#ifndef PROBE_OLD_ABI13
static const st_export_decl exports[] = {{"u_buf", .target = "probe_decl.values_tex"}};
#endif

typedef struct probe {
    st_world *w;
} probe;

static void *create(st_world *w, const double *p, st_err *err) {
    probe *s = st_calloc(sizeof *s, err);
    if (!s) return NULL;
    s->w = w;
#ifndef PROBE_OLD_ABI13 // world-owned objects and exports are ABI 1.4
    const float seven = 7;
    GLuint b = st_world_buffer(w, "probe_decl.values", sizeof seven, &seven, err);
    if (!b || !st_world_buffer_texture(w, "probe_decl.values_tex", b, GL_R32F, err)) {
        free(s);
        return NULL;
    }
#endif
    return s;
}

#ifndef PROBE_OLD_ABI13
static bool needed(void *self, int pass, const st_frame *f) {
    const unsigned again = ST_CHANGE_FIRST | ST_CHANGE_PARAMS | ST_CHANGE_PROGRAMS;
    return f->row != 0 || (f->changes & again);
}
#endif

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    probe *s = self;
    if (!f->shader) return st_fail(err, ST_ERR_RUNTIME, "no program bound for pass %d", pass);
    if (f->row == 0) {
        st_shader_set_int(f->shader, "u_k", f->instance);
    } else {
        const st_target *t = st_world_get_target(s->w, PROBE_NAME ".fill1", err);
        if (!t) return false;
        st_shader_texture(f->shader, "u_fill", GL_TEXTURE_2D, t->color[0]);
    }
    return st_gl_check("probe_decl", err);
}

#ifndef PROBE_OLD_ABI13
ST_PLUGIN(.name = PROBE_NAME, .description = "test plugin with declared passes", ST_PARAMS(params),
          ST_PASSES(passes), ST_EXPORTS(exports), .param_uniforms = "u_", .create = create,
          .destroy = free, .needed = needed, .on_pass = on_pass)
#else
// The 1.4 fields past struct_size hold garbage, which the loader must never read.
static const st_plugin old_desc = {.abi_major = ST_ABI_MAJOR,
                                   .abi_minor = 3,
                                   .struct_size = offsetof(st_plugin, programs),
                                   .name = PROBE_NAME,
                                   .description = "test plugin built as ABI 1.3",
                                   ST_PARAMS(params),
                                   .passes = (const st_pass_decl *)passes,
                                   .num_pass_decls = (int)(sizeof passes / sizeof passes[0]),
                                   .param_uniforms = "u_",
                                   .create = create,
                                   .destroy = free,
                                   .on_pass = on_pass,
                                   .programs = (const st_program_decl *)16,
                                   .num_programs = 1000,
                                   .exports = (const st_export_decl *)24,
                                   .num_exports = 77,
                                   .program = (int (*)(void *, int, const st_frame *))32};
ST_EXPORT const st_plugin *strahl_plugin(void) {
    return &old_desc;
}
#ifndef PROBE_NO_SIZES // probe_decl13h: a hand-written descriptor, minor 3 and nothing else
ST_EXPORT const st_abi_sizes *strahl_plugin_sizes(void) {
    static st_abi_sizes s = ST_ABI_SIZES;
    s.struct_size = offsetof(st_abi_sizes, program_decl);
    s.plugin = offsetof(st_plugin, programs);
    s.frame = offsetof(st_frame, filter);
    s.pass_decl = sizeof(pass_decl13);
    return &s;
}
#endif
#endif
