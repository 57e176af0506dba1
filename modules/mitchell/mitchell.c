// mitchell: volumetric light scattering as a post-process (Mitchell, GPU
// Gems 3 ch. 13; thesis 3.1 and 3.3.2, listings A.2-A.4). Per light (point or sun):
// an occlusion pre-pass (emitters bright, everything else black, at a
// fraction of the screen resolution, bilinear-filtered) and a radial blur of
// it toward the light's screen position added to the scene image in the
// PostProcessor chain. Several lights each blur their own occlusion image
// and the results add up (thesis 3.1).
//
// Nothing runs that the scene does not need: without a scattering medium, or
// when a light's fade (st_godray.h) is 0, its blur pass is not needed and
// the world culls its occlusion pass; a static view reuses the occlusion image.
#include "st_godray.h"
#include "st_world_api.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum {
    P_N,
    P_DENSITY,
    P_DECAY,
    P_WEIGHT,
    P_EXPOSURE,
    P_RESOLUTION,
    P_LIGHT_RADIUS,
    P_SKY,
    P_FADE_MARGIN,
    P_COUNT
};

// Defaults: thesis figure 3.6 (n 100, exposure 0.01921, density 1.4, decay
// 1.0); weight is GPU Gems 3's, absent from the thesis listing A.4 (= 1);
// resolution 1/4 per axis as in figure 3.14; ranges of density and decay
// from thesis 3.1.
static const st_param_def params[P_COUNT] = {
    {"n", ST_PARAM_INT, 100, 1, 512, NULL,
     "blur taps per pixel toward the light (thesis NUM_SAMPLES)"},
    {"density", ST_PARAM_FLOAT, 1.4, 1, 1000, NULL,
     "step = (pixel - light) / (n density): 1 reaches the light, larger gives shorter shafts"},
    {"decay", ST_PARAM_FLOAT, 1.0, 0, 1, NULL,
     "tap i is weighted decay^i (exponential fall-off of the shafts)"},
    {"weight", ST_PARAM_FLOAT, 1.0, 0, 100, NULL,
     "weight of every tap but the pixel's own (GPU Gems 3)"},
    {"exposure", ST_PARAM_FLOAT, 0.01921, 0, 100, NULL,
     "scale of the blurred sum added to the image"},
    {"resolution", ST_PARAM_FLOAT, 0.25, 0.0625, 1, NULL,
     "occlusion image size as a fraction of the screen, per axis (bilinear filtering smooths the "
     "taps)"},
    {"light_radius", ST_PARAM_FLOAT, 0.1, 0.001, 100, NULL,
     "radius in metres of the sphere around each point light that emits (drawn as a screen-facing "
     "disc; a sun is a disc of its angular_diameter)"},
    {"sky", ST_PARAM_FLOAT, 0, 0, 1000, NULL,
     "the thesis' sky: radiance scale of colour (0.2, 0.3, 0.6) added to the scene's background in "
     "the occlusion image; 0 = off"},
    {"fade_margin", ST_PARAM_FLOAT, 0.5, 0.01, 10, NULL,
     "distance outside the screen, in screen heights, over which a light's shafts fade to zero"},
};

static const float SKY_COLOR[3] = {0.2f, 0.3f, 0.6f}; // thesis figure 3.6(a)

enum { OCCLUSION, BLUR }; // table rows

// The light's disc, drawn into the occlusion image after the scene.
enum { PROG_DISC };
static const st_program_decl programs[] = {{"disc", "mitchell/disc.vert", "mitchell/disc.frag"}};

// Per light an occlusion image, owned by the world: `resolution` of the
// screen, with depth for the scene pass, taps outside reading no emitter (no
// clamped edge streaks); then its blur onto the image. The world sets the
// parameters as uniforms u_density, u_decay, u_weight, u_exposure.
static const st_pass_decl passes[] = {
    {{"occlusion", ST_STAGE_PRE, "", "mitchell.occlusion%d", ST_PASS_SCENE},
     .vert = "mitchell/occlusion.vert",
     .frag = "mitchell/occlusion.frag",
     .count = ST_PER_LIGHT,
     .target = {GL_RGBA32F, 1, true, true},
     .scale_param = "resolution"},
    {{"blur", ST_STAGE_POST, "hdr,mitchell.occlusion%d", "hdr",
      ST_PASS_FULLSCREEN | ST_PASS_PIXEL_LOCAL},
     .frag = "mitchell/blur.frag",
     .count = ST_PER_LIGHT},
};

#define MAX_OCC 16 // lights whose occlusion image's offset is kept

typedef struct mitchell {
    st_world *w;
    const double *p;
    GLuint empty_vao;          // the disc's quad has no vertex data
    float occ_jit[MAX_OCC][2]; // the sub-pixel offset each occlusion image was drawn at
} mitchell;

static void destroy(void *self) {
    mitchell *m = self;
    if (m->empty_vao) glDeleteVertexArrays(1, &m->empty_vao);
    free(m);
}

static void *create(st_world *w, const double *p, st_err *err) {
    mitchell *m = st_calloc(sizeof *m, err);
    if (!m) return NULL;
    m->w = w;
    m->p = p;
    glCreateVertexArrays(1, &m->empty_vao);
    return m;
}

static bool needed(void *self, int pass, const st_frame *f) {
    mitchell *m = self;
    if (f->row == BLUR)
        return m->p[P_EXPOSURE] > 0 && st_godray_light_active(f, f->instance, m->p[P_FADE_MARGIN]);
    // The occlusion image depends on the view, the scene and our parameters;
    // it is only drawn when its blur is live (the world culls it otherwise).
    // A box still's jittered frames keep the first frame's and the blur
    // reads it at their own sample (on_pass): redrawn at a quarter of the
    // resolution for each sub-pixel offset, it moved the shafts over whole
    // regions, and few of their pixels could stop accumulating.
    unsigned other =
        ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY | ST_CHANGE_LIGHTS | ST_CHANGE_PARAMS | ST_CHANGE_SIZE;
    if ((f->changes & ST_CHANGE_JITTER) && !(f->changes & other)) return false;
    return f->changes & (other | ST_CHANGE_CAMERA);
}

// The light's emitting region: a sphere of light_radius seen as a
// screen-facing disc of radius r P11 / w (NDC), at the depth of the sphere's
// front, in the light's tint; the sun as a disc of its angular diameter at
// infinity (behind every surface). Below one texel the disc keeps a radius of
// one texel and its radiance is scaled by (r_px / 1)^2, so its summed radiance
// pi r^2 L never aliases away.
typedef struct disc_geom {
    float center[2], extent[2], depth; // NDC
    float center_px[2], radius_px, scale;
} disc_geom;

// c: clip coordinates of the centre, w = c[3] > 0; r / w: the disc's radius in
// view-plane units at unit depth; z: its NDC depth.
static void disc_fill(const float *P, const double c[4], double r, double z, int ow, int oh,
                      disc_geom *d) {
    double w = c[3], rx = r * P[0] / w, ry = r * P[5] / w; // NDC radii
    double r_px = ry * oh / 2, r_draw = r_px > 1 ? r_px : 1;
    double grow = r_draw / r_px; // >= 1
    d->center[0] = (float)(c[0] / w), d->center[1] = (float)(c[1] / w);
    d->extent[0] = (float)(rx * grow + 2.0 / ow), d->extent[1] = (float)(ry * grow + 2.0 / oh);
    d->depth = (float)(z < 1 - 1e-6 ? z : 1 - 1e-6);
    d->center_px[0] = (float)((c[0] / w + 1) * 0.5 * ow),
    d->center_px[1] = (float)((c[1] / w + 1) * 0.5 * oh);
    d->radius_px = (float)r_draw;
    d->scale = (float)(1 / (grow * grow));
}

static bool disc_geometry(const mitchell *m, const st_frame *f, const st_light_desc *l, int ow,
                          int oh, disc_geom *d) {
    const float *vp = f->view_proj, *P = f->proj;
    double c[4];
    if (l->type == ST_LIGHT_DIRECTIONAL) { // w = 0: a point at infinity toward the sun
        for (int i = 0; i < 4; i++)
            c[i] = -((double)vp[i] * l->direction[0] + (double)vp[4 + i] * l->direction[1] +
                     (double)vp[8 + i] * l->direction[2]);
        if (!(c[3] > 1e-6)) return false; // behind: the blur is not needed anyway
        // The disc's angular radius seen at unit distance; at depth 1 - 1e-6.
        disc_fill(P, c, sin(0.5 * st_light_angular_diameter(l)), 1, ow, oh, d);
        return true;
    }
    const float *lp = l->position;
    double r = m->p[P_LIGHT_RADIUS];
    for (int i = 0; i < 4; i++)
        c[i] = (double)vp[i] * lp[0] + (double)vp[4 + i] * lp[1] + (double)vp[8 + i] * lp[2] +
               vp[12 + i];
    double dx = lp[0] - f->cam_pos[0], dy = lp[1] - f->cam_pos[1], dz = lp[2] - f->cam_pos[2];
    double D = sqrt(dx * dx + dy * dy + dz * dz), w = c[3], near_ = f->near_z;
    if (D <= r) { // the camera is inside the light: everything it sees emits
        *d = (disc_geom){{0, 0}, {2, 2}, -1 + 1e-6f, {0, 0}, 1e7f, 1};
        return true;
    }
    if (!(w > near_)) return false; // behind: the blur is not needed anyway
    double wf = w * (D - r) / D;    // view depth of the sphere's front
    if (wf < near_ * 1.0001) wf = near_ * 1.0001;
    disc_fill(P, c, r, (-(double)P[10] * wf + P[14]) / wf, ow, oh, d);
    return true;
}

// Before the world draws the scene into the occlusion image: the sky. The
// scene's background radiance, plus the thesis' sky colour when the `sky`
// parameter asks for it.
static void occlusion_clear(mitchell *m, const st_frame *f) {
    float sky = (float)m->p[P_SKY];
    const float *bg = f->scene->background;
    const float clear[4] = {bg[0] + sky * SKY_COLOR[0], bg[1] + sky * SKY_COLOR[1],
                            bg[2] + sky * SKY_COLOR[2], 1};
    glClearBufferfv(GL_COLOR, 0, clear);
    glClearBufferfv(GL_DEPTH, 0, (const float[]){1.0f});
}

// After the scene: the light's disc, depth-tested against it.
static void after_pass(void *self, int pass, const st_frame *f) {
    mitchell *m = self;
    int k = f->instance;
    char name[ST_NAME_MAX];
    snprintf(name, sizeof name, "mitchell.occlusion%d", k);
    const st_target *t = st_world_target(m->w, name); // bound by the world
    disc_geom d;
    if (f->row != OCCLUSION || !t ||
        !disc_geometry(m, f, &f->scene->lights[k], t->width, t->height, &d))
        return;
    float tint[3];
    st_godray_tint(f->scene->lights, f->scene->num_lights, k, m->p[P_LIGHT_RADIUS], tint);
    for (int c = 0; c < 3; c++)
        tint[c] *= d.scale;
    st_err ignore = {0}; // on_pass compiled it, reporting a failure
    st_shader *sh = st_frame_use_program(f, PROG_DISC, &ignore);
    if (!sh) return;
    st_shader_set_vec2(sh, "u_disc_center", d.center[0], d.center[1]);
    st_shader_set_vec2(sh, "u_disc_extent", d.extent[0], d.extent[1]);
    st_shader_set_float(sh, "u_disc_depth", d.depth);
    st_shader_set_vec2(sh, "u_disc_center_px", d.center_px[0], d.center_px[1]);
    st_shader_set_float(sh, "u_disc_radius_px", d.radius_px);
    st_shader_set_vec3(sh, "u_disc_radiance", tint);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glBindVertexArray(m->empty_vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    mitchell *m = self;
    if (f->row == OCCLUSION) { // the disc's program too, where a failure can be told
        if (f->instance < MAX_OCC)
            m->occ_jit[f->instance][0] = f->jitter[0], m->occ_jit[f->instance][1] = f->jitter[1];
        occlusion_clear(m, f);
        return st_world_program(m->w, m->p, PROG_DISC, err) &&
               st_gl_check("mitchell occlusion", err);
    }
    float tint[3];
    st_godray_light l =
        st_godray_light_state(f, f->instance, m->p[P_FADE_MARGIN], m->p[P_LIGHT_RADIUS], tint);
    char name[ST_NAME_MAX];
    snprintf(name, sizeof name, "mitchell.occlusion%d", f->instance);
    const st_target *occ = st_world_target(m->w, name);
    if (!occ) return st_fail(err, ST_ERR_RUNTIME, "no target %s", name);
    st_shader *sh = f->shader; // bound by the world, builtin uniforms and parameters set
    st_shader_texture(sh, "u_occlusion", GL_TEXTURE_2D, occ->color[0]);
    st_shader_set_vec2(sh, "u_out_size", (float)f->width, (float)f->height);
    st_shader_set_vec2(sh, "u_light_uv", l.uv[0], l.uv[1]);
    // This frame's sample in the occlusion image's frame (x right, y down in
    // pixels; texture v up): 0 unless the image was drawn at another offset.
    const float *o = f->instance < MAX_OCC ? m->occ_jit[f->instance] : f->jitter;
    st_shader_set_vec2(sh, "u_shift", (f->jitter[0] - o[0]) / (float)f->width,
                       -(f->jitter[1] - o[1]) / (float)f->height);
    st_shader_set_int(sh, "u_samples", (int)m->p[P_N]);
    st_shader_set_float(sh, "u_fade", l.fade);
    return st_gl_check("mitchell blur", err);
}

ST_PLUGIN(.name = "mitchell",
          .description = "volumetric light scattering as a post-process (Mitchell, GPU Gems 3): "
                         "radial blur of an occlusion image toward each light",
          ST_PARAMS(params), ST_PASSES(passes), ST_PROGRAMS(programs), .param_uniforms = "u_",
          .create = create, .destroy = destroy, .needed = needed, .on_pass = on_pass,
          .after_pass = after_pass, .light_types = ST_GODRAY_LIGHT_TYPES)
