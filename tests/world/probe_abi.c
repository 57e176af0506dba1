// A test plugin using every ABI 1.4 feature, for test_declared_programs.
// Two compute passes fill array targets with
//   g(x, y, l) = x + 32 y + 512 l + 4096 MODE + 32768 VALUE + data[l]
// (MODE and VALUE compiled in from the parameters `mode` and `value`,
// data[] a world-owned buffer of `cells` floats 0.25 (i + 1)): "grid"
// (3 layers, ST_PASS_PLANE: the program loops over the layers) and "cells"
// (2 layers, one invocation per texel and layer). Both count their
// invocations in a world-owned counter buffer, which on_pass clears with a
// second program (st_frame_use_program). The post pass "show" adds
// (grid(x, y, 2), cells(x, y, 1), data[cells - 1] (+ 0.5 with `alt`)) to the
// image; the program hook picks "show" or "show_alt" by `alt`, or -1 with
// `self`, when on_pass draws it itself. `value`, `mode`, `alt` and the grid
// are exported as uniforms (probe_reader reads them). The test writes the
// GLSL files into <probe dir>/shaders/probe_abi/.
#include "st_world_api.h"
#include <stdlib.h>

enum { P_VALUE, P_MODE, P_ALT, P_SELF, P_CELLS };
static const st_param_def params[] = {
    {"value", ST_PARAM_FLOAT, 2, 0, 8, NULL, "compiled in as PROBE_ABI_VALUE, exported"},
    {"mode", ST_PARAM_INT, 1, 0, 9, NULL, "compiled in as PROBE_ABI_MODE (7: #error), exported"},
    {"alt", ST_PARAM_BOOL, 0, 0, 1, NULL, "the program hook picks show_alt, exported"},
    {"self", ST_PARAM_BOOL, 0, 0, 1, NULL, "the show pass draws itself (program hook -1)"},
    {"cells", ST_PARAM_INT, 4, 1, 64, NULL, "floats in the data buffer"},
};

enum { G_FILL, G_LAYERS, G_ZERO, G_SHOW, G_SHOW_ALT };
static const st_program_decl programs[] = {
    {"fill", .comp = "probe_abi/fill.comp", .defines = "PLANE 1", .param_defines = "value,mode"},
    {"layers", .comp = "probe_abi/fill.comp", .defines = "PLANE 0", .param_defines = "value,mode"},
    {"zero", .comp = "probe_abi/zero.comp"},
    {"show", .frag = "probe_abi/show.frag"},
    {"show_alt", .frag = "probe_abi/show.frag", .defines = "ALT 1"},
};

static const st_pass_decl passes[] = {
    {{"grid", ST_STAGE_PRE, "", "probe_abi.grid", ST_PASS_PLANE},
     .program = "fill",
     .target = {GL_R32F, 1, .type = GL_TEXTURE_2D_ARRAY, .layers = 3, .filter = GL_NEAREST}},
    {{"cells", ST_STAGE_PRE, "", "probe_abi.cells", 0},
     .program = "layers",
     .target = {GL_R32F, 1, .type = GL_TEXTURE_2D_ARRAY, .layers = 2, .filter = GL_NEAREST}},
    {{"show", ST_STAGE_POST, "hdr,probe_abi.grid,probe_abi.cells", "hdr", ST_PASS_FULLSCREEN},
     .program = "show"},
};

static const st_export_decl exports[] = {
    {"u_abi_value", .param = "value"},
    {"u_abi_mode", .param = "mode"},
    {"u_abi_alt", .param = "alt"},
    {"u_abi_grid", .target = "probe_abi.grid"},
};

typedef struct probe {
    st_world *w;
    const double *p;
    GLuint data, data_tex; // the buffer the texture was made over, and the texture
} probe;

static void *create(st_world *w, const double *p, st_err *err) {
    probe *s = st_calloc(sizeof *s, err);
    if (!s) return NULL;
    s->w = w;
    s->p = p;
    // A program no pass names, compiled up front (st_world_program).
    if (!st_world_program(w, p, G_ZERO, err)) {
        free(s);
        return NULL;
    }
    return s;
}

static int program(void *self, int pass, const st_frame *f) {
    probe *s = self;
    if (pass < 2) return pass == 0 ? G_FILL : G_LAYERS;
    if (s->p[P_SELF] != 0) return -1;
    return s->p[P_ALT] != 0 ? G_SHOW_ALT : G_SHOW;
}

// The data buffer (uploaded every frame) and the counters, cleared by the
// "zero" program before the first compute pass.
static bool buffers(probe *s, const st_frame *f, st_err *err) {
    float data[64];
    int n = (int)s->p[P_CELLS];
    for (int i = 0; i < n; i++)
        data[i] = 0.25f * (float)(i + 1);
    GLuint d = st_world_buffer(s->w, "probe_abi.data", (size_t)n * sizeof(float), data, err);
    GLuint c = st_world_buffer(s->w, "probe_abi.count", 4 * sizeof(GLuint), NULL, err);
    if (!d || !c) return false;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, c);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, d);
    if (f->row != 0) return true;
    if (!st_frame_use_program(f, G_ZERO, err)) return false;
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    return true;
}

static bool show(probe *s, const st_frame *f, st_err *err) {
    st_shader *sh = f->shader;
    if (s->p[P_SELF] != 0) { // the program hook said -1: draw with our own call
        if (f->shader) return st_fail(err, ST_ERR_RUNTIME, "a program bound for a -1 pass");
        sh = st_frame_use_program(f, s->p[P_ALT] != 0 ? G_SHOW_ALT : G_SHOW, err);
        if (!sh) return false;
    }
    const st_target *cells = st_world_get_target(s->w, "probe_abi.cells", err);
    GLuint d =
        st_world_buffer(s->w, "probe_abi.data", (size_t)s->p[P_CELLS] * sizeof(float), NULL, err);
    if (!cells || !d) return false;
    if (d != s->data) { // a new buffer (its size changed): a texture over it
        s->data_tex = st_world_buffer_texture(s->w, "probe_abi.data_tex", d, GL_R32F, err);
        if (!s->data_tex) return false;
        s->data = d;
    }
    st_shader_texture(sh, "u_cells", GL_TEXTURE_2D_ARRAY, cells->color[0]);
    st_shader_texture(sh, "u_data", GL_TEXTURE_BUFFER, s->data_tex);
    st_shader_set_int(sh, "u_cells_n", (int)s->p[P_CELLS]);
    if (s->p[P_SELF] != 0) st_draw_fullscreen();
    return true;
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    probe *s = self;
    bool ok = f->row < 2 ? buffers(s, f, err) : show(s, f, err);
    return ok && st_gl_check("probe_abi", err);
}

ST_PLUGIN(.name = "probe_abi", .description = "test plugin using every ABI 1.4 feature",
          .provides = "probe_abi", ST_PARAMS(params), ST_PROGRAMS(programs), ST_PASSES(passes),
          ST_EXPORTS(exports), .create = create, .destroy = free, .on_pass = on_pass,
          .program = program)
