// A test plugin with declared passes (ABI 1.3), for test_declared_passes.
// Per light a pre-pass fills its own target "probe_decl.fill<k>" (R32F,
// `scale` of the screen) with value + 100 k; one post pass adds
// (value * GAIN, fill1, 0) to the image. Its programs are files in
// <probe dir>/shaders/probe_decl/, which the test writes and rewrites (hot
// reload). The plugin loads no program and declares no target itself.
#include "st_world_api.h"
#include <stdlib.h>

static const st_param_def params[] = {
    {"value", ST_PARAM_FLOAT, 3, -1000, 1000, NULL, "set as the uniform u_value"},
    {"scale", ST_PARAM_FLOAT, 1, 0.0625, 1, NULL, "size of the fill targets"},
};

static const st_pass_decl passes[] = {
    {{"fill", ST_STAGE_PRE, "", "probe_decl.fill%d", ST_PASS_FULLSCREEN},
     .frag = "probe_decl/fill.frag",
     .count = ST_PER_LIGHT,
     .target = {GL_R32F, 1},
     .scale_param = "scale"},
    {{"add", ST_STAGE_POST, "hdr,probe_decl.fill1", "hdr", ST_PASS_FULLSCREEN},
     .frag = "probe_decl/add.frag"},
};

typedef struct probe {
    st_world *w;
} probe;

static void *create(st_world *w, const double *p, st_err *err) {
    probe *s = st_calloc(sizeof *s, err);
    if (s) s->w = w;
    return s;
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    probe *s = self;
    if (!f->shader) return st_fail(err, ST_ERR_RUNTIME, "no program bound for pass %d", pass);
    if (f->row == 0) {
        st_shader_set_int(f->shader, "u_k", f->instance);
    } else {
        const st_target *t = st_world_get_target(s->w, "probe_decl.fill1", err);
        if (!t) return false;
        st_shader_texture(f->shader, "u_fill", GL_TEXTURE_2D, t->color[0]);
    }
    return st_gl_check("probe_decl", err);
}

ST_PLUGIN(.name = "probe_decl", .description = "test plugin with declared passes",
          ST_PARAMS(params), ST_PASSES(passes), .param_uniforms = "u_", .create = create,
          .destroy = free, .on_pass = on_pass)
