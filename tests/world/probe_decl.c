// A test plugin with declared passes (ABI 1.3), for test_declared_passes.
// Per light a pre-pass fills its own target "probe_decl.fill<k>" (R32F,
// `scale` of the screen) with value + 100 k; one post pass adds
// (value * GAIN, fill1, 0) to the image. Its programs are files in
// <probe dir>/shaders/probe_decl/, which the test writes and rewrites (hot
// reload). The plugin loads no program and declares no target itself.
// ABI 1.4: a world-owned buffer texture "probe_decl.values_tex" holding 7,
// exported as u_buf (the add pass puts it in blue); the fill passes run only
// on their first frame, a parameter change or a shader reload
// (ST_CHANGE_PROGRAMS), their target keeping its texels between.
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

static const st_export_decl exports[] = {{"u_buf", .target = "probe_decl.values_tex"}};

typedef struct probe {
    st_world *w;
} probe;

static void *create(st_world *w, const double *p, st_err *err) {
    probe *s = st_calloc(sizeof *s, err);
    if (!s) return NULL;
    s->w = w;
    const float seven = 7;
    GLuint b = st_world_buffer(w, "probe_decl.values", sizeof seven, &seven, err);
    if (!b || !st_world_buffer_texture(w, "probe_decl.values_tex", b, GL_R32F, err)) {
        free(s);
        return NULL;
    }
    return s;
}

static bool needed(void *self, int pass, const st_frame *f) {
    const unsigned again = ST_CHANGE_FIRST | ST_CHANGE_PARAMS | ST_CHANGE_PROGRAMS;
    return f->row != 0 || (f->changes & again);
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
          ST_PARAMS(params), ST_PASSES(passes), ST_EXPORTS(exports), .param_uniforms = "u_",
          .create = create, .destroy = free, .needed = needed, .on_pass = on_pass)
