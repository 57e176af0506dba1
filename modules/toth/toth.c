// toth: single scattering (Toth & Umenhoffer 2009) in the scene's
// homogeneous medium, as post passes on the camera's gbuffer.
// sampling=equiangular (default): the in-scattered light is the unshadowed
// integral times each light's visible fraction.
//   march   (march resolution)  the visible fraction of every light along the
//           view ray, parametrized by the angle seen from the light (Kulla &
//           Fajardo 2012): steps with equal shares of a density that is half
//           the unshadowed integrand, half uniform in that angle, shadow_map
//           lookups at both ends of each step, a boundary inside a step
//           located by bisection
//   gather  (M > 1 only)  averages the fractions of the M x M block
//   edges   (below full resolution)  marches the full-resolution pixels whose
//           upsampling taps disagree or show another surface, into
//           toth.refined; drawn as one point per block, the blocks without
//           such a pixel culled in the vertex shader (llvmpipe would run the
//           march code masked for every pixel of a full-screen pass)
//   compose (full resolution)  the unshadowed integral per pixel: a point
//           light's from the airlight table (airlight.h, compose=table), a
//           spot's by Gauss-Legendre in that angle, times the fraction
//           upsampled depth-aware (or the edges pass's), added to the image
//           the regular pass attenuated by e^(-sigma_t s)
// sampling=uniform: the march sums the in-scattered light of equal steps
// (Hillaire's energy-conserving step, or the thesis' Riemann sums with
// integrator=thesis/thesis_far), interleaved over M x M pixels, gathered and
// upsampled; the brute-force baseline. Without a medium, with sigma_s = 0 or
// without lights no pass runs: the view ray's extinction belongs to the
// regular pass (docs/physics.md), toth only adds in-scattered light.
#include "airlight.h"
#include "st_world.h"
#include "st_physics.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    P_SAMPLES,
    P_INTERLEAVE,
    P_JITTER,
    P_RESOLUTION,
    P_INTEGRATOR,
    P_TOLERANCE,
    P_SAMPLING,
    P_NODES,
    P_REFINE,
    P_BISECT,
    P_REFINE_TAPS,
    P_MIN_ROWS,
    P_EXACT,
    P_COMPOSE,
    P_GLOW,
    P_GLOW_RADIUS,
    P_PROBES,
    P_REFINE_KINK,
    P_COUNT
};
enum { SAMPLING_UNIFORM, SAMPLING_EQUIANGULAR };
enum { COMPOSE_TABLE, COMPOSE_QUADRATURE };

// Defaults (the Pareto front against the CPU reference, docs/benchmarks.md,
// tools/bench_all.sh ONLY=truth): equi-angular sampling, the visible
// fraction marched at half resolution (at least 48 rows) in 64 steps with
// 4 halvings per shadow boundary, pixels whose upsampling taps disagree by
// more than 0.2 (or show another surface) marched at full resolution, the
// unshadowed integral per full-resolution pixel from the airlight table.
// Half resolution, not quarter: a shaft crossed at a grazing angle leaves
// lit slivers and kinks in the visible fraction that quarter-resolution
// upsampling smears (256x192 against the reference, rmse: godrays_window
// quarter 1.35e-4, half 7.8e-5, the 1024-step full-resolution march 9.5e-5;
// godrays_hidden_hole 2.04e-4, 1.14e-4, 8.2e-5). 128 steps take window and
// hidden_hole to 6.3e-5 and 9.0e-5 for twice the march's time.
static const st_param_def params[P_COUNT] = {
    {"samples", ST_PARAM_INT, 64, 1, 1024, NULL,
     "march steps per view ray (split over the M x M block when interleaved)"},
    {"interleave", ST_PARAM_INT, 1, 1, 8, NULL,
     "M: each pixel of an M x M block marches every M^2-th step, a geometry-aware gather sums them "
     "(1 = off; limited to sqrt(samples))"},
    {"jitter", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "per-pixel offset of the samples within their steps (banding -> noise)"},
    {"resolution", ST_PARAM_ENUM, 1, 0, 0, "full|half|quarter",
     "march resolution (raised where the march would have fewer than min_rows rows); below full, "
     "the in-scattered light is upsampled depth-aware"},
    {"integrator", ST_PARAM_ENUM, 0, 0, 0, "energy|thesis|thesis_far",
     "energy: Hillaire's step, exact for a constant source; thesis: the thesis' Riemann sum "
     "(source at the near end of each step); thesis_far: at the far end"},
    {"edge_tolerance", ST_PARAM_FLOAT, 0.1, 0.001, 10, NULL,
     "relative difference in surface distance up to which gather and upsampling mix two pixels"},
    {"sampling", ST_PARAM_ENUM, SAMPLING_EQUIANGULAR, 0, 0, "uniform|equiangular",
     "uniform: steps of equal length, the march sums the in-scattered light (integrator applies); "
     "equiangular: steps equal in the angle seen from the light, the march finds each light's "
     "visible "
     "fraction and the unshadowed integral is evaluated per full-resolution pixel"},
    {"nodes", ST_PARAM_INT, 16, 4, 64, NULL,
     "equiangular: Gauss-Legendre nodes of the per-pixel unshadowed integral (rounded up to a "
     "multiple of 4)"},
    {"refine", ST_PARAM_FLOAT, 0.2, 0, 1, NULL,
     "equiangular below full resolution: a pixel whose upsampling taps differ in visible fraction "
     "by "
     "more than this (or show another surface) marches its own ray at full resolution (1 = never)"},
    {"bisect", ST_PARAM_INT, 4, 0, 8, NULL,
     "equiangular: halvings that locate a shadow boundary inside a step (0 = trapezoid of the "
     "step's "
     "two lookups)"},
    {"refine_taps", ST_PARAM_INT, 4, 1, 4, NULL,
     "equiangular below full resolution: a pixel with fewer upsampling taps on its own surface "
     "inside the image than this marches its own ray, unless all four taps are inside the image "
     "and see exactly the same fraction (4: every silhouette, crease and border pixel; 2: only "
     "where at most one tap is usable)"},
    {"min_rows", ST_PARAM_INT, 48, 0, 4096, NULL,
     "the march resolution is raised (quarter -> half -> full) until the march has at least this "
     "many rows (0 = resolution as set)"},
    {"exact_edges", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "equiangular: lookups the shadow map cannot decide (shadow_map.refine's rule) take an exact "
     "ray against the scene's BVH (needs shadow_map.refine), boundaries are bisected with exact "
     "rays (4 more halvings), and agreeing ends near an edge have their midpoint traced"},
    {"compose", ST_PARAM_ENUM, COMPOSE_TABLE, 0, 0, "table|quadrature",
     "equiangular: a point light's unshadowed integral per pixel from the airlight table (two "
     "lookups per channel) or by `nodes` Gauss-Legendre nodes (spots always use the nodes)"},
    {"glow", ST_PARAM_INT, 4, 1, 16, NULL,
     "equiangular, box filter: pixels whose ray passes a point or spot light within glow_radius "
     "pixels integrate its unshadowed in-scattering over their square with glow x glow sub-rays "
     "(1 = the frame's one jittered ray)"},
    {"glow_radius", ST_PARAM_FLOAT, 8, 0, 64, NULL,
     "equiangular, box filter: distance from a light's projection, in pixels, within which "
     "`glow` applies"},
    {"probes", ST_PARAM_INT, 3, 0, 7, NULL,
     "equiangular: shadow-map lookups inside a step whose two ends agree; one that disagrees "
     "splits "
     "the step there (finds lit slivers and thin occluders between the ends)"},
    {"refine_kink", ST_PARAM_FLOAT, 0.01, 0, 1, NULL,
     "equiangular below full resolution: a block whose march texel's visible fraction has a "
     "second difference (along its row or column) above this marches its pixels' own rays (0 = "
     "off)"},
};

enum { PASS_MARCH, PASS_GATHER, PASS_EDGES, PASS_COMPOSE };

typedef struct toth {
    st_world *w;
    const double *p;
    struct toth_shaders {
        st_shader *march, *gather, *edges, *compose;
    } sh;
    GLuint vao; // the edges pass's points (attribute-less)
    st_pass_info info;
    int height;     // image rows the targets were declared for
    int decl_scale; // the divisor they were declared with
    // The airlight table (compose=table) and the phase function it holds.
    GLuint airlight;
    st_phase_kind table_kind;
    float table_g;
    float *table;
} toth;

// Steps cannot be shared by more pixels than there are steps.
static int interleave(const toth *t) {
    int m = (int)t->p[P_INTERLEAVE], n = (int)t->p[P_SAMPLES];
    while (m > 1 && m * m > n)
        m--;
    return m;
}

// The march's divisor for an image `height` rows high. A march of fewer
// than min_rows rows is too coarse for shafts a few pixels wide: most
// pixels then disagree with their taps and are marched again at full
// resolution, which costs more than a finer march (96x96 window_hg of the
// cross-check: half resolution faster than quarter and closer to Cycles), so
// the divisor halves until the march has that many rows.
static int scale(const toth *t, int height) {
    int s = 1 << (int)t->p[P_RESOLUTION];
    while (s > 1 && height / s < (int)t->p[P_MIN_ROWS])
        s /= 2;
    return s;
}

// The pass a slot index stands for (the gather exists only when interleaved).
static int pass_kind(const toth *t, int pass) {
    int g = interleave(t) > 1;
    if (pass == 0) return PASS_MARCH;
    if (pass == 1 && g) return PASS_GATHER;
    return pass == 1 + g ? PASS_EDGES : PASS_COMPOSE;
}

static bool medium_scatters(const st_scene *sc) {
    const st_medium_desc *m = &sc->medium;
    return m->present && (m->sigma_s[0] > 0 || m->sigma_s[1] > 0 || m->sigma_s[2] > 0);
}

// The march (and, interleaved, the gather) output at march resolution, owned
// by the world: the screen divided by the scale, rounded up. Every read is a
// texelFetch; nearest keeps a stray sampled read honest.
// Re-declared when the image height moves the divisor (min_rows).
static bool declare_targets(toth *t, int height, st_err *err) {
    t->height = height;
    t->decl_scale = scale(t, height);
    const st_target_desc d = {GL_RGBA32F, .divisor = t->decl_scale, .filter = GL_NEAREST};
    // The edges pass's fractions, full resolution (-1: not marched there).
    const st_target_desc full = {GL_RGBA32F, .divisor = 1, .filter = GL_NEAREST};
    return st_world_declare_target(t->w, "toth.march", &d, err) &&
           st_world_declare_target(t->w, "toth.gather", interleave(t) > 1 ? &d : NULL, err) &&
           st_world_declare_target(t->w, "toth.refined", &full, err);
}

static void destroy_shaders(struct toth_shaders *sh) {
    st_shader_destroy(sh->march);
    st_shader_destroy(sh->gather);
    st_shader_destroy(sh->edges);
    st_shader_destroy(sh->compose);
    *sh = (struct toth_shaders){0};
}

static bool load_shaders(st_world *w, const double *p, struct toth_shaders *sh, st_err *err) {
    const char *defines = st_world_light_defines(w);
    char cdef[256];
    snprintf(cdef, sizeof cdef, "%s%s", defines,
             p[P_COMPOSE] == COMPOSE_TABLE ? "TOTH_AIRLIGHT 1\n" : "");
    const char *vs = "common/fullscreen.vert";
    *sh = (struct toth_shaders){0};
    if ((sh->march = st_shader_load(vs, "toth/march.frag", defines, err)) &&
        (sh->gather = st_shader_load(vs, "toth/gather.frag", defines, err)) &&
        (sh->edges = st_shader_load("toth/edges.vert", "toth/edges.frag", defines, err)) &&
        (sh->compose = st_shader_load(vs, "toth/compose.frag", cdef, err)))
        return true;
    destroy_shaders(sh);
    return false;
}

static void *create(st_world *w, const double *p, st_err *err) {
    toth *t = calloc(1, sizeof *t);
    if (!t) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    t->w = w;
    t->p = p;
    if (!declare_targets(t, st_world_scene(w)->height, err) || !load_shaders(w, p, &t->sh, err)) {
        free(t);
        return NULL;
    }
    return t;
}

static void destroy(void *self) {
    toth *t = self;
    destroy_shaders(&t->sh);
    if (t->vao) glDeleteVertexArrays(1, &t->vao);
    free(t->table);
    free(t);
}

static int num_passes(void *self) {
    return interleave(self) > 1 ? 4 : 3;
}

static const st_pass_info *pass_info(void *self, int pass) {
    toth *t = self;
    switch (pass_kind(t, pass)) {
    case PASS_MARCH:
        t->info = (st_pass_info){"march", ST_STAGE_POST, "gbuffer,shadow_map", "toth.march",
                                 ST_PASS_FULLSCREEN};
        break;
    case PASS_GATHER:
        t->info = (st_pass_info){"gather", ST_STAGE_POST, "gbuffer,toth.march", "toth.gather",
                                 ST_PASS_FULLSCREEN};
        break;
    case PASS_EDGES: // draws its own points (on_pass)
        t->info = (st_pass_info){"edges", ST_STAGE_POST,
                                 interleave(t) > 1 ? "gbuffer,shadow_map,toth.gather"
                                                   : "gbuffer,shadow_map,toth.march",
                                 "toth.refined", 0};
        break;
    default:
        t->info = (st_pass_info){"compose", ST_STAGE_POST,
                                 interleave(t) > 1 ? "hdr,gbuffer,toth.gather,toth.refined"
                                                   : "hdr,gbuffer,toth.march,toth.refined",
                                 "hdr", ST_PASS_FULLSCREEN};
        break;
    }
    return &t->info;
}

// A varying density (medium.density) has no closed-form unshadowed
// integral: its view rays are marched (sampling=uniform, march_density.glsl).
static int sampling(const toth *t, const st_scene *sc) {
    return st_density_varies(&sc->density) ? SAMPLING_UNIFORM : (int)t->p[P_SAMPLING];
}

// Nothing runs without a scattering medium or without lights: toth adds
// in-scattered light only (the regular pass applies the view's extinction).
static bool needed(void *self, int pass, const st_frame *f) {
    toth *t = self;
    // needed() runs for every pass before the world binds targets: a new
    // image height that changes the march divisor re-declares them here.
    if (pass == 0 && scale(t, f->height) != t->decl_scale) {
        st_err ignore = {0}; // only fails for a bad name, which create already caught
        declare_targets(t, f->height, &ignore);
    }
    bool any = medium_scatters(f->scene) && f->scene->num_lights > 0;
    // The edges pass: only where compose may read it (equi-angular below full
    // resolution, refine < 1).
    if (pass_kind(t, pass) == PASS_EDGES)
        return any && sampling(t, f->scene) == SAMPLING_EQUIANGULAR && t->decl_scale > 1 &&
               (t->p[P_REFINE] < 1 || t->p[P_REFINE_KINK] > 0);
    return any;
}

// The airlight table of the scene's phase function (compose=table), filled
// when the phase function changes: 256 x 1024 texels, ~1M phase evaluations.
static GLuint airlight_table(toth *t, const st_medium_desc *m, st_err *err) {
    const st_target *tg = st_world_target(t->w, "toth.airlight");
    if (tg && t->table && t->table_kind == m->phase && t->table_g == m->g) return tg->color[0];
    const st_target_desc d = {GL_R32F, .width = TOTH_AIRLIGHT_NXI, .height = TOTH_AIRLIGHT_NU,
                              .filter = GL_LINEAR};
    tg = st_world_alloc_target(t->w, "toth.airlight", &d, err);
    if (!tg) return 0;
    if (!t->table) t->table = malloc(sizeof(float) * TOTH_AIRLIGHT_NXI * TOTH_AIRLIGHT_NU);
    if (!t->table) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory (toth airlight table)");
        return 0;
    }
    toth_airlight_fill(t->table, m->phase, m->g);
    glTextureSubImage2D(tg->color[0], 0, 0, 0, TOTH_AIRLIGHT_NXI, TOTH_AIRLIGHT_NU, GL_RED,
                        GL_FLOAT, t->table);
    t->table_kind = m->phase;
    t->table_g = m->g;
    return tg->color[0];
}

static void set_common(toth *t, st_shader *sh) {
    st_shader_set_int(sh, "toth_scale", t->decl_scale);
    st_shader_set_float(sh, "toth_tolerance", (float)t->p[P_TOLERANCE]);
    st_shader_set_int(sh, "toth_interleave", interleave(t));
}

// The edges pass: one point per scale x scale block (edges.vert keeps those
// with a pixel that may need its own ray), drawn into toth.refined after
// clearing it to -1 (compose then upsamples every pixel not marched here).
static bool draw_edges(toth *t, const st_frame *f, const st_target *src, st_err *err) {
    st_shader *sh = t->sh.edges;
    int s = t->decl_scale, bx = (f->width + s - 1) / s, by = (f->height + s - 1) / s;
    set_common(t, sh);
    st_shader_set_int(sh, "toth_blocks_x", bx);
    st_shader_set_int(sh, "toth_samples", (int)t->p[P_SAMPLES]);
    st_shader_set_int(sh, "toth_jitter", t->p[P_JITTER] != 0);
    st_shader_set_int(sh, "toth_bisect", (int)t->p[P_BISECT]);
    st_shader_set_int(sh, "toth_exact", t->p[P_EXACT] != 0);
    st_shader_set_int(sh, "toth_probes", (int)t->p[P_PROBES]);
    st_shader_set_float(sh, "toth_refine", (float)t->p[P_REFINE]);
    st_shader_set_int(sh, "toth_refine_taps", (int)t->p[P_REFINE_TAPS]);
    st_shader_set_float(sh, "toth_refine_kink", (float)t->p[P_REFINE_KINK]);
    if (!src) return st_fail(err, ST_ERR_RUNTIME, "toth: no march target");
    st_shader_texture(sh, "toth_inscatter_tex", GL_TEXTURE_2D, src->color[0]);
    const float none[4] = {-1, -1, -1, -1};
    glClearBufferfv(GL_COLOR, 0, none);
    if (!t->vao) glCreateVertexArrays(1, &t->vao);
    glBindVertexArray(t->vao);
    glPointSize((float)s);
    glDrawArrays(GL_POINTS, 0, bx * by);
    glPointSize(1.0f);
    return true;
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    toth *t = self;
    struct toth_shaders *sh = &t->sh;
    const st_target *src = st_world_target(t->w, interleave(t) > 1 ? "toth.gather" : "toth.march");
    // march and gather draw into the target they write, bound by the world.
    switch (pass_kind(t, pass)) {
    case PASS_MARCH:
        set_common(t, sh->march);
        st_shader_set_int(sh->march, "toth_samples", (int)t->p[P_SAMPLES]);
        st_shader_set_int(sh->march, "toth_jitter", t->p[P_JITTER] != 0);
        st_shader_set_int(sh->march, "toth_integrator", (int)t->p[P_INTEGRATOR]);
        st_shader_set_int(sh->march, "toth_sampling", sampling(t, f->scene));
        st_shader_set_int(sh->march, "toth_bisect", (int)t->p[P_BISECT]);
        st_shader_set_int(sh->march, "toth_exact", t->p[P_EXACT] != 0);
        st_shader_set_int(sh->march, "toth_probes", (int)t->p[P_PROBES]);
        break;
    case PASS_GATHER: {
        const st_target *march = st_world_get_target(t->w, "toth.march", err);
        if (!march) return false;
        set_common(t, sh->gather);
        st_shader_set_int(sh->gather, "toth_sampling", sampling(t, f->scene));
        st_shader_texture(sh->gather, "toth_march_tex", GL_TEXTURE_2D, march->color[0]);
        break;
    }
    case PASS_EDGES:
        if (!draw_edges(t, f, src, err)) return false;
        break;
    default: {
        const st_target *refined = st_world_target(t->w, "toth.refined");
        set_common(t, sh->compose);
        st_shader_set_int(sh->compose, "toth_sampling", sampling(t, f->scene));
        st_shader_set_int(sh->compose, "toth_nodes", (int)t->p[P_NODES]);
        st_shader_set_float(sh->compose, "toth_refine", (float)t->p[P_REFINE]);
        st_shader_set_int(sh->compose, "toth_refine_taps", (int)t->p[P_REFINE_TAPS]);
        st_shader_set_float(sh->compose, "toth_refine_kink", (float)t->p[P_REFINE_KINK]);
        st_shader_set_int(sh->compose, "toth_has_inscatter", src != NULL);
        st_shader_set_int(sh->compose, "toth_glow", (int)t->p[P_GLOW]);
        st_shader_set_float(sh->compose, "toth_glow_radius", (float)t->p[P_GLOW_RADIUS]);
        if (src) st_shader_texture(sh->compose, "toth_inscatter_tex", GL_TEXTURE_2D, src->color[0]);
        if (refined)
            st_shader_texture(sh->compose, "toth_refined_tex", GL_TEXTURE_2D, refined->color[0]);
        if (t->p[P_COMPOSE] == COMPOSE_TABLE) {
            GLuint table = airlight_table(t, &f->scene->medium, err);
            if (!table) return false;
            st_shader_texture(sh->compose, "toth_airlight_tex", GL_TEXTURE_2D, table);
        }
        break;
    }
    }
    return st_gl_check("toth pass", err);
}

static st_shader *shader(void *self, int pass) {
    toth *t = self;
    switch (pass_kind(t, pass)) {
    case PASS_MARCH:
        return t->sh.march;
    case PASS_GATHER:
        return t->sh.gather;
    case PASS_EDGES:
        return t->sh.edges;
    default:
        return t->sh.compose;
    }
}

static bool reload(void *self, st_err *err) {
    toth *t = self;
    struct toth_shaders sh;
    if (!load_shaders(t->w, t->p, &sh, err)) return false;
    destroy_shaders(&t->sh);
    t->sh = sh;
    return true;
}

// A new march scale or interleave re-describes the targets; a new compose
// method recompiles the shaders (on failure the old ones stay).
static void param_changed(void *self, int index) {
    st_err ignore = {0}; // only fails for a bad name, which create already caught
    if (index == P_RESOLUTION || index == P_INTERLEAVE || index == P_SAMPLES || index == P_MIN_ROWS)
        declare_targets(self, ((toth *)self)->height, &ignore);
    if (index == P_COMPOSE) reload(self, &ignore);
}

ST_PLUGIN(.name = "toth",
          .description =
              "single scattering in a homogeneous medium (Toth & Umenhoffer 2009): equi-angular "
              "per-pixel integral times a shadow-mapped visible fraction (or the uniform march), "
              "interleaved sampling, reduced-resolution march",
          ST_PARAMS(params), .requires = "shadow_map", .create = create, .destroy = destroy,
          .num_passes = num_passes, .pass_info = pass_info, .needed = needed, .on_pass = on_pass,
          .shader = shader, .param_changed = param_changed, .reload = reload,
          .light_types = ST_LIGHT_BITS_ALL)
