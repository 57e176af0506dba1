// ssgi: the screen-space baseline for atlas_gi. The same one-bounce
// estimators (shaders/atlas_gi/estimator.glsl), but the senders are drawn
// from the camera's G-buffer: N Hammersley samples over the image's pixels,
// each pixel standing for the surface patch it sees (area = its solid angle
// times distance^2 over the cosine to the view ray). Surfaces out of view or
// hidden contribute nothing, so the indirect light changes with the camera:
// the artifact the atlas removes, measurable against atlas_gi.
#include "st_world.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { P_SAMPLES, P_ESTIMATOR, P_DISPLAY, P_MIN_COS, P_COUNT };

static const st_param_def params[P_COUNT] = {
    {"samples", ST_PARAM_INT, 100, 1, 4096, NULL, "Hammersley samples over the image per pixel"},
    {"estimator", ST_PARAM_ENUM, 0, 0, 1, "area|thesis", "the same estimators as atlas_gi"},
    {"display", ST_PARAM_ENUM, 0, 0, 1, "combined|indirect",
     "combined: the image plus indirect; indirect only"},
    {"min_cos", ST_PARAM_FLOAT, 0.05, 0.001, 1, NULL,
     "a pixel's surface patch is at most 1/min_cos times its perpendicular footprint (grazing "
     "views)"},
};

typedef struct ssgi {
    st_world *w;
    const double *p;
    st_shader *sh;
    int ham_n;
    st_pass_info info;
} ssgi;

static void *create(st_world *w, const double *p, st_err *err) {
    ssgi *s = st_calloc(sizeof *s, err);
    if (!s) return NULL;
    s->w = w;
    s->p = p;
    s->sh = st_shader_load("common/fullscreen.vert", "ssgi/gather.frag", NULL, err);
    if (!s->sh) {
        free(s);
        return NULL;
    }
    return s;
}

static void destroy(void *self) {
    ssgi *s = self;
    st_shader_destroy(s->sh);
    free(s);
}

static int num_passes(void *self) {
    return 1;
}

static const st_pass_info *pass_info(void *self, int pass) {
    ssgi *s = self;
    s->info =
        (st_pass_info){"gather", ST_STAGE_POST, "hdr,gbuffer,albedo", "hdr", ST_PASS_FULLSCREEN};
    return &s->info;
}

static st_shader *shader(void *self, int pass) {
    return ((ssgi *)self)->sh;
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    ssgi *s = self;
    int n = (int)s->p[P_SAMPLES];
    // The sample set of atlas_gi, over the image: a 1D lookup the world owns.
    const st_target_desc d = {GL_RG32F, .type = GL_TEXTURE_1D, .width = n, .filter = GL_NEAREST};
    const st_target *ham = st_world_alloc_target(s->w, "ssgi.hammersley", &d, err);
    if (!ham) return false;
    if (s->ham_n != n && !st_hammersley_upload(ham->color[0], n, NULL))
        return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    s->ham_n = n;
    st_shader_texture(s->sh, "ss_hammersley", GL_TEXTURE_1D, ham->color[0]);
    st_shader_set_int(s->sh, "ss_samples", s->ham_n);
    st_shader_set_int(s->sh, "ss_estimator", (int)s->p[P_ESTIMATOR]);
    st_shader_set_int(s->sh, "ss_display", (int)s->p[P_DISPLAY]);
    st_shader_set_float(s->sh, "ss_min_cos", (float)s->p[P_MIN_COS]);
    return st_gl_check("ssgi", err);
}

static bool reload(void *self, st_err *err) {
    return st_shader_reload(((ssgi *)self)->sh, err);
}

ST_PLUGIN(.name = "ssgi",
          .description =
              "screen-space one-bounce gather from the camera's G-buffer (baseline for atlas_gi)",
          ST_PARAMS(params), .create = create, .destroy = destroy, .num_passes = num_passes,
          .pass_info = pass_info, .shader = shader, .on_pass = on_pass, .reload = reload,
          .light_types = ST_LIGHT_BITS_ALL /* direct light through common/lighting.glsl */)
