// A test plugin without tables (the hooks of ABI 1.2 and 1.3), for
// test_declared_programs: its shader hook answers a compute program it loads
// itself, and on_pass dispatches it over its target probe_hook.t (20 x 12
// in 8 x 8 groups), which counts its invocations in the world-owned buffer
// probe_hook.count. The world must not dispatch such a pass a second time:
// it dispatches only the programs it owns (ST_PROGRAMS).
#include "st_world_api.h"
#include <stdlib.h>

typedef struct probe {
    st_world *w;
    st_shader *sh;
} probe;

static const st_pass_info info = {"count", ST_STAGE_PRE, "", "probe_hook.t", ST_PASS_SIDE_EFFECT};

static void destroy(void *self) {
    probe *s = self;
    if (s) st_shader_destroy(s->sh);
    free(s);
}

static void *create(st_world *w, const double *p, st_err *err) {
    (void)p;
    probe *s = st_calloc(sizeof *s, err);
    if (!s) return NULL;
    s->w = w;
    const st_target_desc d = {GL_R32F, 1};
    if (!(s->sh = st_shader_load_compute("probe_hook/count.comp", NULL, err)) ||
        !st_world_declare_target(w, "probe_hook.t", &d, err)) {
        destroy(s);
        return NULL;
    }
    return s;
}

static int num_passes(void *self) {
    (void)self;
    return 1;
}

static const st_pass_info *pass_info(void *self, int pass) {
    (void)self, (void)pass;
    return &info;
}

static st_shader *shader(void *self, int pass) {
    (void)pass;
    return ((probe *)self)->sh;
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    (void)pass;
    probe *s = self;
    const GLuint zero[1] = {0};
    GLuint c = st_world_buffer(s->w, "probe_hook.count", sizeof zero, zero, err);
    const st_target *t = st_world_get_target(s->w, "probe_hook.t", err);
    if (!c || !t) return false;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, c);
    glBindImageTexture(0, t->color[0], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glDispatchCompute((GLuint)(f->width + 7) / 8, (GLuint)(f->height + 7) / 8, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    return st_gl_check("probe_hook", err);
}

ST_PLUGIN(.name = "probe_hook", .description = "test plugin dispatching its own compute program",
          .create = create, .destroy = destroy, .num_passes = num_passes, .pass_info = pass_info,
          .shader = shader, .on_pass = on_pass)
