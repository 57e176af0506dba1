// froxel: volumetric fog in a camera-aligned grid (Hillaire 2015, "Physically
// based and unified volumetric rendering in Frostbite"; the method of
// Unreal's volumetric fog and Bevy's). Three passes per frame:
//   inject    (compute, one thread per froxel)  the density and the
//             in-scattered radiance per metre at the froxel's sample point:
//             every light, its shadow_map visibility, the phase function and
//             the light's transmittance to the point (docs/physics.md)
//   integrate (compute, one thread per column)  front to back along the
//             column's ray with Hillaire's energy-conserving step:
//             in-scattered light and optical depth from the camera to the end
//             of every slice
//   compose   (full resolution)  each pixel looks its own depth up: the
//             integral to the start of its slice plus the partial step to
//             the surface (or, where it sees none, to the far plane), added
//             to the image the regular pass attenuated by the view ray's
//             transmittance (docs/physics.md: froxel only adds light)
// The grid covers the screen in x and y (image / tile, or grid_x x grid_y)
// and the view depth [0, far] in `slices` exponential slices. Without a
// scattering medium or without lights no pass runs.
#include "st_world_api.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    P_TILE,
    P_MIN_ROWS,
    P_GRID_X,
    P_GRID_Y,
    P_SLICES,
    P_FAR,
    P_EXPONENT,
    P_NEAR_FIELD,
    P_NEAR_RADIUS,
    P_JITTER,
    P_TEMPORAL,
    P_HISTORY,
    P_TAPS,
    P_COUNT
};

static const st_param_def params[P_COUNT] = {
    {"tile", ST_PARAM_INT, 8, 1, 64, NULL,
     "froxel footprint in pixels: the grid is the image divided by it, rounded up (unless "
     "grid_x / grid_y are set)"},
    {"min_rows", ST_PARAM_INT, 64, 0, 256, NULL,
     "the tile shrinks until the grid has at least this many rows (small images keep the "
     "shafts' resolution; 0 = tile as set)"},
    {"grid_x", ST_PARAM_INT, 0, 0, 256, NULL, "froxel columns (0 = image width / tile)"},
    {"grid_y", ST_PARAM_INT, 0, 0, 256, NULL, "froxel rows (0 = image height / tile)"},
    {"slices", ST_PARAM_INT, 128, 1, 256, NULL, "depth slices between the camera and far"},
    {"far", ST_PARAM_FLOAT, 0, 0, 1e6, NULL,
     "view depth the grid ends at (0 = the camera's far plane); no in-scattering beyond it"},
    {"exponent", ST_PARAM_FLOAT, 3, 0, 30, NULL,
     "depth distribution: slice boundary z(u) = far (e^(k u) - 1) / (e^k - 1), u = k / slices "
     "(0 = linear; larger = thinner slices near the camera)"},
    {"near_field", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "point and spot lights: the part of 1/d^2 within about a froxel of the light, which the grid "
     "cannot resolve, integrated along each pixel's ray (unshadowed); off: the plain method"},
    {"near_radius", ST_PARAM_FLOAT, 2, 0.25, 16, NULL,
     "the near field's radius in froxels (the larger of a froxel's width and its slice's length "
     "at the light's depth), times tile / 4 pixels where the tile is wider"},
    {"jitter", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "a box still's jittered frames reuse its first frame's grid, read at each frame's sample "
     "position: the still is the mean over each pixel of the point frame's answer (off: every "
     "frame recomputes the grid through its jittered projection)"},
    {"temporal", ST_PARAM_BOOL, 0, 0, 1, NULL,
     "temporal reprojection (Hillaire 2015): each frame samples its froxels at another depth in "
     "their slices and blends them with the previous frame's grid, reprojected (off for stills: "
     "the first frame is the plain one, later ones converge to the slice average)"},
    {"history", ST_PARAM_FLOAT, 0.9, 0, 0.99, NULL,
     "temporal: the reprojected history's weight in the blend"},
    {"taps", ST_PARAM_ENUM, 0, 0, 1, "center|footprint",
     "where a froxel's source is evaluated: at its sample point (center), or the mean of 4 "
     "points spread over the froxel (footprint: the slice's Gauss nodes on the ray, each "
     "moved across the cell), each with the density, shadow_map visibility and the light's "
     "transmittance there"},
};

// The programs, compiled with the light defines. The taps are a compile-time
// choice (FROXEL_TAPS, the enum's index): llvmpipe runs both sides of a
// branch on a uniform, so the 4 taps' lookups would cost the single-tap
// program too.
// inject_still: a box still's first frame, whose grid its jittered frames
// reuse (begin_frame), takes the slice's mean along the column's ray (8
// midpoints, each with its shadow lookup) whatever `taps` says: with the
// slice midpoint alone fog_room's still against Cycles went from NRMSE 0.030
// (the former per-frame jitter) to 0.052, with 8 midpoints 0.031.
enum { PROG_INJECT, PROG_INTEGRATE, PROG_COMPOSE, PROG_INJECT_STILL };
static const st_program_decl programs[] = {
    [PROG_INJECT] = {"inject", .comp = "froxel/inject.comp", .param_defines = "taps",
                     .flags = ST_PROGRAM_LIGHTS},
    [PROG_INTEGRATE] = {"integrate", .comp = "froxel/integrate.comp", .flags = ST_PROGRAM_LIGHTS},
    [PROG_COMPOSE] = {"compose", .frag = "froxel/compose.frag", .flags = ST_PROGRAM_LIGHTS},
    [PROG_INJECT_STILL] = {"inject_still", .comp = "froxel/inject.comp",
                           .defines = "FROXEL_TAPS 1\nFROXEL_TAP_SPREAD 0.0\nFROXEL_MIDPOINTS 8",
                           .flags = ST_PROGRAM_LIGHTS},
};

// inject: one invocation per froxel, over froxel.inject (bound at image unit
// 0 by the world); integrate: one per column (ST_PASS_PLANE), writing
// froxel.integrated at unit 0 and reading froxel.inject at unit 1; compose:
// the image. The volumes are declared below (their size is the grid's).
enum { PASS_INJECT, PASS_INTEGRATE, PASS_COMPOSE };
static const st_pass_decl passes[] = {
    {{"inject", ST_STAGE_POST, "shadow_map", "froxel.inject", 0}, .program = "inject"},
    {{"integrate", ST_STAGE_POST, "froxel.inject", "froxel.integrated", ST_PASS_PLANE},
     .program = "integrate"},
    {{"compose", ST_STAGE_POST, "hdr,gbuffer,froxel.inject,froxel.integrated", "hdr",
      ST_PASS_FULLSCREEN | ST_PASS_PIXEL_LOCAL},
     .program = "compose"},
};

typedef struct froxel {
    st_world *w;
    const double *p;
    int gx, gy, gz; // the grid the targets were declared for
    int fw, fh;     // the last frame's size (0 before the first)
    // temporal: the previous frame's matrices, and whether froxel.history
    // holds that frame's grid
    float prev_view_proj[16], prev_view[16], prev_cam[3];
    bool has_history;
    int history_frames; // frames blended since the history was last reset
    // A box still's grid: `kept` when the volumes hold its first (centred)
    // frame's grid, `reusing` when this frame reads them instead of
    // recomputing them (its only change is the sub-pixel jitter).
    bool kept, reusing;
} froxel;

// The grid for an image of w x h pixels: square tiles of `tile` pixels, made
// smaller where that would give fewer than min_rows rows, unless given
// explicitly. A shrunk tile stays a whole number of pixels (1 at most sizes
// under 2 min_rows: a 96 x 96 image gets 96 x 96 columns): with a fractional
// tile the columns fall on a pixel centre, then between two, in a repeating
// pattern, and the bilinear lookup's error beats with it into blocks (on
// vdb_cloud at 96 x 72, 64 rows: NRMSE 0.092; 72 rows: see README).
static void grid_size(const froxel *x, int w, int h, int *gx, int *gy) {
    double tile = x->p[P_TILE], rows = x->p[P_MIN_ROWS];
    if (rows > 0 && h / tile < rows) tile = fmax(floor(h / rows), 1.0);
    *gx = x->p[P_GRID_X] > 0 ? (int)x->p[P_GRID_X] : (int)ceil(w / tile - 1e-9);
    *gy = x->p[P_GRID_Y] > 0 ? (int)x->p[P_GRID_Y] : (int)ceil(h / tile - 1e-9);
    *gx = *gx < 1 ? 1 : *gx > 1024 ? 1024 : *gx;
    *gy = *gy < 1 ? 1 : *gy > 1024 ? 1024 : *gy;
}

// Two world-owned volumes as 2D arrays (one layer per slice): `inject` holds
// the source and density per froxel, `integrated` the integral to the end of
// each slice. Linear in x and y (the compose pass interpolates columns), the
// slices are read one by one.
static bool declare_targets(froxel *x, int w, int h, st_err *err) {
    if (w < 1 || h < 1) { // before the first frame: the scene's size
        w = st_world_scene(x->w)->width;
        h = st_world_scene(x->w)->height;
    }
    grid_size(x, w, h, &x->gx, &x->gy);
    x->gz = (int)x->p[P_SLICES];
    const st_target_desc d = {GL_RGBA32F, .type = GL_TEXTURE_2D_ARRAY, .width = x->gx,
                              .height = x->gy, .layers = x->gz};
    x->has_history = false;
    x->history_frames = 0;
    x->kept = false;
    return st_world_declare_target(x->w, "froxel.inject", &d, err) &&
           st_world_declare_target(x->w, "froxel.integrated", &d, err) &&
           st_world_declare_target(x->w, "froxel.history", x->p[P_TEMPORAL] != 0 ? &d : NULL, err);
}

static void *create(st_world *w, const double *p, st_err *err) {
    froxel *x = st_calloc(sizeof *x, err);
    if (!x) return NULL;
    x->w = w;
    x->p = p;
    if (!declare_targets(x, 0, 0, err)) {
        free(x);
        return NULL;
    }
    return x;
}

static bool medium_scatters(const st_scene *sc) {
    const st_medium_desc *m = &sc->medium;
    return m->present && (m->sigma_s[0] > 0 || m->sigma_s[1] > 0 || m->sigma_s[2] > 0);
}

// Whether this frame's grid is kept for a box still's jittered frames.
static bool keeps_grid(const froxel *x, const st_frame *f) {
    return x->p[P_JITTER] != 0 && x->p[P_TEMPORAL] == 0 && f->filter == ST_FILTER_BOX;
}

// A box still's jittered frames reuse the grid of its first frame (centred,
// slice midpoints) with `jitter` on and `temporal` off: the grid does not
// change with a sub-pixel offset (columns a whole pixel or more apart), so
// only compose runs, reading the grid at the frame's sample position, and
// the still is the mean over each pixel's square of the point frame's
// answer. Recomputing the grid per frame cost ~1 s a frame on fog_room at
// 96 x 72 for hundreds of frames.
static void begin_frame(froxel *x, const st_frame *f, bool any) {
    const unsigned jitter_only = ST_CHANGE_CAMERA | ST_CHANGE_JITTER | ST_CHANGE_INPUTS;
    x->reusing = any && x->kept && keeps_grid(x, f) && (f->changes & ST_CHANGE_JITTER) &&
                 !(f->changes & ~jitter_only);
    // The volumes hold a still's first frame's grid once inject runs on it.
    if (!x->reusing) x->kept = any && keeps_grid(x, f) && f->jitter[0] == 0 && f->jitter[1] == 0;
}

// needed() runs before the world binds targets: a new image size that moves
// an automatic grid re-declares the volumes here.
static bool needed(void *self, int pass, const st_frame *f) {
    froxel *x = self;
    int gx, gy;
    bool any = medium_scatters(f->scene) && f->scene->num_lights > 0;
    x->fw = f->width, x->fh = f->height;
    grid_size(x, f->width, f->height, &gx, &gy);
    if (pass == PASS_INJECT && (gx != x->gx || gy != x->gy)) {
        st_err ignore = {0}; // only fails for a bad name, which create already caught
        declare_targets(x, f->width, f->height, &ignore);
    }
    if (pass == PASS_INJECT) begin_frame(x, f, any);
    return any && (pass == PASS_COMPOSE || !x->reusing);
}

// Where inside its slice a froxel is sampled this frame: the midpoint, or
// with jitter the base-2 radical inverse of the frame index (accumulated
// stills average them).
static float slice_offset(const froxel *x, uint64_t frame) {
    if (x->p[P_TEMPORAL] == 0) return 0.5f;
    double r = 0, f = 0.5;
    for (uint64_t n = frame; n; n >>= 1, f *= 0.5)
        r += f * (double)(n & 1);
    return (float)fmod(r + 0.5, 1.0);
}

static void set_grid(const froxel *x, st_shader *sh, const st_frame *f) {
    float far = x->p[P_FAR] > 0 ? (float)x->p[P_FAR] : f->far_z;
    glUniform3i(st_shader_loc(sh, "froxel_grid"), x->gx, x->gy, x->gz);
    st_shader_set_float(sh, "froxel_far", far);
    st_shader_set_float(sh, "froxel_exponent", (float)x->p[P_EXPONENT]);
    st_shader_set_float(sh, "froxel_offset", slice_offset(x, f->index));
    st_shader_set_int(sh, "froxel_reuse", x->reusing);
    st_shader_set_int(sh, "froxel_near_field", x->p[P_NEAR_FIELD] != 0);
    st_shader_set_float(sh, "froxel_near_scale", (float)x->p[P_NEAR_RADIUS]);
}

// The program of a pass: a kept grid is the froxels' footprint mean (the
// still's frames then average the pixel, not one point of each froxel).
static int program(void *self, int pass, const st_frame *f) {
    const froxel *x = self;
    if (pass == PASS_INJECT) return keeps_grid(x, f) ? PROG_INJECT_STILL : PROG_INJECT;
    return pass == PASS_INTEGRATE ? PROG_INTEGRATE : PROG_COMPOSE;
}

// inject's temporal inputs: the history (image unit 2) and the previous
// frame's matrices.
static bool inject_history(froxel *x, st_shader *sh, st_err *err) {
    const st_target *hist = NULL;
    if (x->p[P_TEMPORAL] != 0 && !(hist = st_world_get_target(x->w, "froxel.history", err)))
        return false;
    st_shader_set_int(sh, "froxel_temporal", hist && x->has_history);
    st_shader_set_float(sh, "froxel_history", (float)x->p[P_HISTORY]);
    st_shader_set_mat4(sh, "froxel_prev_view_proj", x->prev_view_proj);
    st_shader_set_mat4(sh, "froxel_prev_view", x->prev_view);
    glUniform3fv(st_shader_loc(sh, "froxel_prev_cam"), 1, x->prev_cam);
    if (hist) glBindImageTexture(2, hist->color[0], 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    return true;
}

// The world dispatches inject and integrate over the target each writes and
// draws compose; here their other inputs.
static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    froxel *x = self;
    st_shader *sh = f->shader;
    const st_target *in = st_world_get_target(x->w, "froxel.inject", err);
    const st_target *vol = in ? st_world_get_target(x->w, "froxel.integrated", err) : NULL;
    if (!vol) return false;
    set_grid(x, sh, f);
    if (pass == PASS_INJECT) return inject_history(x, sh, err);
    if (pass == PASS_INTEGRATE) {
        glBindImageTexture(1, in->color[0], 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
        return st_gl_check("froxel integrate", err);
    }
    st_shader_texture(sh, "froxel_inject_tex", GL_TEXTURE_2D_ARRAY, in->color[0]);
    st_shader_texture(sh, "froxel_integrated_tex", GL_TEXTURE_2D_ARRAY, vol->color[0]);
    return st_gl_check("froxel compose", err);
}

// temporal: this frame's grid becomes the next one's history.
static void after_pass(void *self, int pass, const st_frame *f) {
    froxel *x = self;
    const st_target *in = st_world_target(x->w, "froxel.inject");
    const st_target *hist = x->p[P_TEMPORAL] != 0 ? st_world_target(x->w, "froxel.history") : NULL;
    if (pass != PASS_INJECT || !in || !hist) return;
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    glCopyImageSubData(in->color[0], GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, hist->color[0],
                       GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, x->gx, x->gy, x->gz);
    memcpy(x->prev_view_proj, f->view_proj, sizeof x->prev_view_proj);
    memcpy(x->prev_view, f->view, sizeof x->prev_view);
    memcpy(x->prev_cam, f->cam_pos, sizeof x->prev_cam);
    x->history_frames += x->has_history;
    x->has_history = true;
}

// temporal: frames until the first frame's weight in the blend, history^n,
// is below 1%; a still runs at least that many (the box filter starts
// accumulating after them). Without temporal froxel is exact for its grid
// at once and reports nothing.
static int history_need(const froxel *x) {
    double h = x->p[P_HISTORY];
    return h <= 0 ? 0 : (int)ceil(log(0.01) / log(h));
}

static bool progress(void *self, st_progress *out) {
    froxel *x = self;
    if (x->p[P_TEMPORAL] == 0) return false;
    out->converged = x->history_frames >= history_need(x);
    out->frames = (uint32_t)x->history_frames;
    out->error = pow(x->p[P_HISTORY], x->history_frames);
    snprintf(out->info, sizeof out->info, "temporal: %d of %d frames blended (%dx%dx%d froxels)",
             x->history_frames, history_need(x), x->gx, x->gy, x->gz);
    return true;
}

static void param_changed(void *self, int index) {
    froxel *x = self;
    st_err ignore = {0}; // only fails for a bad name, which create already caught
    if (index == P_TILE || index == P_MIN_ROWS || index == P_TEMPORAL || index == P_GRID_X ||
        index == P_GRID_Y || index == P_SLICES)
        declare_targets(x, x->fw, x->fh, &ignore);
}

ST_PLUGIN(.name = "froxel",
          .description = "volumetric fog in a camera-aligned froxel grid (Hillaire 2015): "
                         "per-froxel density and in-scattering from every light with shadow-map "
                         "visibility, front-to-back energy-conserving integration, looked up "
                         "per pixel",
          ST_PARAMS(params), ST_PROGRAMS(programs), ST_PASSES(passes), .requires = "shadow_map",
          .provides = ST_CAP_INSCATTER, .create = create, .destroy = free, .needed = needed,
          .program = program, .on_pass = on_pass, .after_pass = after_pass,
          .param_changed = param_changed, .progress = progress, .light_types = ST_LIGHT_BITS_ALL)
