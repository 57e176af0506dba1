// ssgi: the screen-space baseline for atlas_gi. The same one-bounce
// estimators (shaders/common/estimator.glsl), but the senders are drawn
// from the camera's G-buffer: N Hammersley samples over the image's pixels,
// each pixel standing for the surface patch it sees (area = its solid angle
// times distance^2 over the cosine to the view ray). Surfaces out of view or
// hidden contribute nothing, so the indirect light changes with the camera:
// the artifact the atlas removes, measurable against atlas_gi.
#include "st_world_api.h"
#include <stdlib.h>

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

// One post pass; the world loads its program and sets the parameters as
// uniforms ss_samples, ss_estimator, ss_display, ss_min_cos.
static const st_pass_decl passes[] = {
    {{"gather", ST_STAGE_POST, "hdr,gbuffer,albedo", "hdr", ST_PASS_FULLSCREEN},
     .frag = "ssgi/gather.frag"},
};

// The instance is the sample count uploaded so far.
static void *create(st_world *w, const double *p, st_err *err) {
    return st_calloc(sizeof(int), err);
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    int n = (int)f->params[P_SAMPLES], *uploaded = self;
    // The sample set of atlas_gi, over the image: a 1D lookup the world owns.
    const st_target_desc d = {GL_RG32F, .type = GL_TEXTURE_1D, .width = n, .filter = GL_NEAREST};
    const st_target *ham = st_world_alloc_target(f->world, "ssgi.hammersley", &d, err);
    if (!ham) return false;
    if (*uploaded != n && !st_hammersley_upload(ham->color[0], n, NULL))
        return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    *uploaded = n;
    st_shader_texture(f->shader, "ss_hammersley", GL_TEXTURE_1D, ham->color[0]);
    return st_gl_check("ssgi", err);
}

ST_PLUGIN(.name = "ssgi",
          .description =
              "screen-space one-bounce gather from the camera's G-buffer (baseline for atlas_gi)",
          ST_PARAMS(params), ST_PASSES(passes), .param_uniforms = "ss_", .create = create,
          .destroy = free, .on_pass = on_pass,
          .light_types = ST_LIGHT_BITS_ALL /* direct light through common/lighting.glsl */)
