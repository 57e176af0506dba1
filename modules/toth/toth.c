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
//           toth.refined: a select step drawn as one point per block (the
//           blocks without such a pixel culled in the vertex shader) lists
//           those pixels, a march step runs one fragment per listed pixel,
//           packed densely (llvmpipe runs 4 x 4 blocks in 8-wide vectors: a
//           lane that does not march waits for its neighbours that do)
//   compose (full resolution)  the unshadowed integral per pixel: a point
//           light's from the airlight table (airlight.h, compose=table), a
//           spot's by Gauss-Legendre in that angle, times the fraction
//           upsampled depth-aware, kinks placed between two lines
//           (upsample_kink), or the edges pass's, added to the image
//           the regular pass attenuated by e^(-sigma_t s)
//   keep    (reuse=on, box stills)  the first frame's fractions per pixel
//           and a copy of its gbuffer; the jittered frames that follow run
//           compose alone and read them at their sub-pixel position
//           (shaders/toth/reuse.glsl)
// sampling=uniform: the march sums the in-scattered light of equal steps
// (Hillaire's energy-conserving step, or the thesis' Riemann sums with
// integrator=thesis/thesis_far), interleaved over M x M pixels, gathered and
// upsampled; the brute-force baseline. Without a medium, with sigma_s = 0 or
// without lights no pass runs: the view ray's extinction belongs to the
// regular pass (docs/physics.md), toth only adds in-scattered light.
#include "airlight.h"
#include "st_gl.h"
#include "st_physics.h"
#include "st_world_api.h"
#include <math.h>
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
    P_PROBES,
    P_REFINE_KINK,
    P_REUSE,
    P_UPSAMPLE_KINK,
    P_COUNT
};
enum { SAMPLING_UNIFORM, SAMPLING_EQUIANGULAR };
enum { COMPOSE_TABLE, COMPOSE_QUADRATURE };

// Defaults (the Pareto front against the CPU reference, docs/benchmarks.md,
// "toth's defaults near real time (issue 35)"): equi-angular sampling, the
// visible fraction marched at a third of the resolution (at least 48 rows)
// in 32 steps with 3 probes each and exact rays where the map is undecided,
// pixels whose upsampling taps disagree by more than 0.2 (or show another
// surface) or whose block bends by more than 0.05 (refine_kink; 0.01
// before) marched at full resolution, the
// unshadowed integral per full-resolution pixel from the airlight table.
// The cheapest setting measured at no more than half the 1024-step
// full-resolution march's rmse on godrays_window and godrays_hidden_hole
// (320x240): the former defaults (half resolution, 64 steps, refine_kink
// 0.01) had a sixth to a fifth of it in 2.3-3.2x the frame; a third with 24
// or 28 steps just misses it on hidden_hole, quarter resolution needs
// refine_kink's full-resolution blocks to reach it and costs more. Without
// kink blocks godrays_colonnade's thin shafts miss it (0.53x); 0.05 takes
// it to 0.29x for ~1.1x the frame, 0.01 to 0.14x for 1.3-1.7x.
static const st_param_def params[P_COUNT] = {
    {"samples", ST_PARAM_INT, 0, 0, 1024, NULL,
     "march steps per view ray (split over the M x M block when interleaved; 0 = 32 equi-angular, "
     "64 uniform, which a varying density always marches); on llvmpipe at "
     "most 256 equi-angular steps per ray (samples / M^2): more is refused there, as Mesa's loop "
     "budget would cut the march short; with exact_edges on a scene of more than 2368 triangles "
     "the limit shrinks with the BVH's depth, 256 x 10.2 / (log2(triangles / 4) + 1) (10^5 "
     "triangles: 167; the error names it)"},
    {"interleave", ST_PARAM_INT, 1, 1, 8, NULL,
     "M: each pixel of an M x M block marches every M^2-th step, a geometry-aware gather sums them "
     "(1 = off; limited to sqrt(samples))"},
    {"jitter", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "per-pixel offset of the samples within their steps (banding -> noise)"},
    {"resolution", ST_PARAM_ENUM, 3, 0, 0, "full|half|quarter|third",
     "march resolution: every 1st, 2nd, 4th or 3rd pixel in x and y (raised where the march would "
     "have fewer than min_rows rows); below full, the in-scattered light is upsampled depth-aware"},
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
    // 64, not 16 (issue 35): a spot in view puts its cone's edges, kinks of
    // the integrand, close together near the apex, where 16 nodes left
    // spot_fog's pixels there 1-2% off (320x240 rmse 3.4e-4 against the CPU
    // reference, the 1024-step march 1.5e-4; 32 nodes 7.7e-5, 64 4.0e-5)
    // for 1.9x compose's time there (+25% of the frame); points use the
    // airlight table.
    {"nodes", ST_PARAM_INT, 64, 4, 64, NULL,
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
     "than this, or beyond the outermost march pixels (the image border), marches its own ray, "
     "unless its four taps (at the border mirrored inward) see exactly the same fraction (4: every "
     "silhouette and crease pixel; 2: only where at most one tap is usable)"},
    {"min_rows", ST_PARAM_INT, 48, 0, 4096, NULL,
     "the march resolution is raised (quarter or third -> half -> full) until the march has at "
     "least this "
     "many rows (0 = resolution as set)"},
    {"exact_edges", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "equiangular: lookups the shadow map cannot decide (shadow_map.refine's rule) take an exact "
     "ray against the scene's BVH (needs shadow_map.refine), boundaries are located from the "
     "blocking triangle's shadow volume and checked by rays (bisection with 4 more halvings as "
     "the fallback), and agreeing ends near an edge have their midpoint traced"},
    {"compose", ST_PARAM_ENUM, COMPOSE_TABLE, 0, 0, "table|quadrature",
     "equiangular: a point light's unshadowed integral per pixel from the airlight table (two "
     "lookups per channel) or by `nodes` Gauss-Legendre nodes (spots always use the nodes)"},
    {"glow", ST_PARAM_INT, 4, 1, 16, NULL,
     "equiangular, box filter: pixels whose ray passes a point or spot light within 8 pixels "
     "(TOTH_GLOW_RADIUS_PX) integrate its unshadowed in-scattering over their square with glow x "
     "glow sub-rays (1 = the frame's one jittered ray)"},
    {"probes", ST_PARAM_INT, 3, 0, 7, NULL,
     "equiangular: shadow-map lookups inside a step whose two ends agree; one that disagrees "
     "splits the step there (finds lit slivers and thin occluders between the ends); a step "
     "whose ends disagree is split there too where they see a second boundary"},
    {"refine_kink", ST_PARAM_FLOAT, 0.05, 0, 1, NULL,
     "equiangular below full resolution: a block whose march texel's visible fraction has a "
     "second difference (along its row or column) above this marches its pixels' own rays (0 = "
     "off)"},
    {"reuse", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "equiangular, box filter: the jittered frames of a still do not march; they read the first "
     "frame's visible fraction at their sub-pixel position, bilinear on the same surface (off: "
     "every frame marches its own rays)"},
    {"upsample_kink", ST_PARAM_FLOAT, 0.001, 0, 1, NULL,
     "equiangular below full resolution: where the visible fraction's second difference over "
     "the 4 x 4 march texels around a pixel (all on its surface) exceeds this, the upsampling "
     "places a kink between two lines instead of interpolating bilinearly (0 = bilinear)"},
};

// Tuning constants that no scene, test or benchmark varies (the parameters
// glow_radius and exact_solve before toth moved to the declared tables):
// - TOTH_GLOW_RADIUS_PX: distance from a point or spot light's projection,
//   in pixels, within which `glow` integrates the pixel's square (box
//   filter; README "A light in view under the box filter");
// - TOTH_EXACT_SOLVE: with exact_edges, a shadow boundary is located in
//   closed form from the blocking triangle's shadow volume and checked by
//   ~3.4 BVH rays; 0 bisects with bisect + 4 exact rays (8). Measured at the
//   switch (docs/benchmarks.md, fifth run): no higher rmse (window 9.409e-5
//   -> 9.392e-5, hidden_hole 5.674e-5 -> 5.660e-5) for fewer rays.
#define TOTH_GLOW_RADIUS_PX 8.0f
#define TOTH_EXACT_SOLVE 1

// The programs the world compiles, hot-reloads and deletes: the passes'
// rows' when the module loads, the others on first use (march.comp for a
// small march, the reuse programs only when a box still reuses). compose's
// parameter is compiled in (TOTH_COMPOSE 0: the airlight table, compose.frag).
enum {
    PROG_MARCH,
    PROG_MARCH_CS,
    PROG_GATHER,
    PROG_EDGES,
    PROG_EDGES_MARCH,
    PROG_COMPOSE,
    PROG_KEEP,
    PROG_COMPOSE_REUSE
};
static const st_program_decl programs[] = {
    [PROG_MARCH] = {"march", .frag = "toth/march.frag", .flags = ST_PROGRAM_LIGHTS},
    [PROG_MARCH_CS] = {"march_cs", .comp = "toth/march.comp", .flags = ST_PROGRAM_LIGHTS},
    [PROG_GATHER] = {"gather", .frag = "toth/gather.frag", .flags = ST_PROGRAM_LIGHTS},
    [PROG_EDGES] = {"edges", "toth/edges.vert", "toth/edges.frag", .flags = ST_PROGRAM_LIGHTS},
    [PROG_EDGES_MARCH] = {"edges_march", "toth/edges_march.vert", "toth/edges_march.frag",
                          .flags = ST_PROGRAM_LIGHTS},
    [PROG_COMPOSE] = {"compose", .frag = "toth/compose.frag", .param_defines = "compose",
                      .flags = ST_PROGRAM_LIGHTS},
    [PROG_KEEP] = {"keep", .frag = "toth/keep.frag", .flags = ST_PROGRAM_LIGHTS},
    [PROG_COMPOSE_REUSE] = {"compose_reuse", .frag = "toth/compose.frag", .defines = "TOTH_REUSE 1",
                            .param_defines = "compose", .flags = ST_PROGRAM_LIGHTS},
};

// The passes. Their targets are declared by declare_targets (the march's
// divisor follows the image height); `needed` skips what does not apply
// (the gather when not interleaved, the edges pass at full resolution, the
// keep pass without reuse) and the program hook picks the march's program
// (drawn or dispatched) and compose's (reusing or not).
enum { PASS_MARCH, PASS_GATHER, PASS_EDGES, PASS_KEEP, PASS_COMPOSE };
static const st_pass_decl passes[] = {
    [PASS_MARCH] = {{"march", ST_STAGE_POST, "gbuffer,shadow_map", "toth.march",
                     ST_PASS_FULLSCREEN},
                    .program = "march"},
    [PASS_GATHER] = {{"gather", ST_STAGE_POST, "gbuffer,toth.march", "toth.gather",
                      ST_PASS_FULLSCREEN},
                     .program = "gather"},
    // Draws its own points and quad (select_edges, march_edges).
    [PASS_EDGES] = {{"edges", ST_STAGE_POST, "gbuffer,shadow_map,toth.march,toth.gather",
                     "toth.refined", 0},
                    .program = "edges"},
    [PASS_KEEP] = {{"keep", ST_STAGE_POST, "gbuffer,toth.march,toth.gather,toth.refined",
                    "toth.first", ST_PASS_FULLSCREEN}},
    [PASS_COMPOSE] = {{"compose", ST_STAGE_POST,
                       "hdr,gbuffer,toth.march,toth.gather,toth.refined,toth.first", "hdr",
                       ST_PASS_FULLSCREEN | ST_PASS_PIXEL_LOCAL},
                      .program = "compose"},
};

typedef struct toth {
    st_world *w;
    const double *p;
    // The edges pass's points and quad (attribute-less), and the framebuffer
    // without attachments of grid_w x grid_h pixels its march step draws
    // into: GL objects the world does not own (it owns targets and buffers).
    GLuint vao, list_fbo;
    int grid_w, grid_h;
    int height;     // image rows the targets were declared for
    bool dispatch;  // this frame's march is dispatched (march.comp), not drawn
    int decl_scale; // the divisor they were declared with
    // The phase function the airlight table (compose=table) holds.
    st_phase_kind table_kind;
    float table_g;
    float *table;
    // reuse=on: this frame is a jittered one that reads the first frame's
    // fractions (kept: they exist, from the view-projection first_vp).
    bool reusing, kept;
    float first_vp[16];
} toth;

// The steps per view ray: `samples`, or where it is 0 (the default) the
// defaults' 32 equi-angular steps (issue 35) and the uniform march's 64, as
// before: a varying density is marched uniformly, and its cross-checks
// against Cycles (vdb_cloud 0.042 against a bound of 0.05) have no margin
// for twice the step (their images moved by 2.5-3.2% of the mean at 32).
#define TOTH_AUTO_EQUIANGULAR_STEPS 32
#define TOTH_AUTO_UNIFORM_STEPS 64
static int sampling(const toth *t, const st_scene *sc);
static int steps(const toth *t) {
    int n = (int)t->p[P_SAMPLES];
    if (n > 0) return n;
    return sampling(t, st_world_scene(t->w)) == SAMPLING_EQUIANGULAR ? TOTH_AUTO_EQUIANGULAR_STEPS
                                                                     : TOTH_AUTO_UNIFORM_STEPS;
}

// Steps cannot be shared by more pixels than there are steps.
static int interleave(const toth *t) {
    int m = (int)t->p[P_INTERLEAVE], n = steps(t);
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
// `third` (appended to keep the enum's values) marches the centre pixel of
// each 3 x 3 block: 2.25x fewer rays than half, and the block's centre is a
// pixel (an even divisor's is not), so the upsampling's taps sit symmetric.
static int scale(const toth *t, int height) {
    static const int divisor[] = {1, 2, 4, 3};
    int s = divisor[(int)t->p[P_RESOLUTION]];
    while (s > 1 && height / s < (int)t->p[P_MIN_ROWS])
        s = s == 3 ? 2 : s / 2;
    return s;
}

static bool reuse_on(const toth *t) {
    return t->p[P_REUSE] != 0;
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
    // reuse=on: the first frame's fractions and gbuffer (keep pass).
    const st_target_desc *keep = reuse_on(t) ? &full : NULL;
    t->kept = false;
    return st_world_declare_target(t->w, "toth.march", &d, err) &&
           st_world_declare_target(t->w, "toth.gather", interleave(t) > 1 ? &d : NULL, err) &&
           st_world_declare_target(t->w, "toth.refined", &full, err) &&
           st_world_declare_target(t->w, "toth.first", keep, err) &&
           st_world_declare_target(t->w, "toth.first_gbuffer", keep, err);
}

static void *create(st_world *w, const double *p, st_err *err) {
    toth *t = calloc(1, sizeof *t);
    if (!t) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    t->w = w;
    t->p = p;
    if (!declare_targets(t, st_world_scene(w)->height, err)) {
        free(t);
        return NULL;
    }
    return t;
}

static void destroy(void *self) {
    toth *t = self;
    if (t->vao) glDeleteVertexArrays(1, &t->vao);
    if (t->list_fbo) glDeleteFramebuffers(1, &t->list_fbo);
    free(t->table);
    free(t);
}

// A varying density (medium.density) has no closed-form unshadowed
// integral: its view rays are marched (sampling=uniform, march_density.glsl).
static int sampling(const toth *t, const st_scene *sc) {
    return st_density_varies(&sc->density) ? SAMPLING_UNIFORM : (int)t->p[P_SAMPLING];
}

// llvmpipe gives a shader invocation (8 lanes) one budget of 65535 loop
// iterations for all its loops and then leaves every loop silently (Mesa's
// gallivm, lp_exec_endloop): the equi-angular march's steps, probes and
// exact rays run out of it between 384 steps (still exact, godrays_window
// 320x240) and 512 (whole shaft edges dark, rmse 1.2e-6 -> 6.5e-5), so a
// ray may take at most 256 of them there. A GPU driver has no such budget.
#define TOTH_LLVMPIPE_MAX_STEPS 256
// Those 256 steps hold on scenes of up to this many triangles (the god-ray
// scenes, godrays_light_front's 2368 the most; test_toth_scenes marches
// each at 256). An exact ray (exact_edges) walks shadow_map.refine's BVH
// (binned SAH, leaves of 4 triangles) in loop iterations that grow with its
// depth, about log2(n / 4) + 1: on a larger scene a ray may take 256 x
// depth(ref) / depth(n) steps there (10^5 triangles: 167), as if every
// iteration of a step were the BVH's. A bound from the tree's shape that
// errs towards refusing, not a measurement on such a scene.
#define TOTH_LLVMPIPE_REF_TRIANGLES 2368

static double bvh_depth(double triangles) {
    return log2(fmax(triangles, 4.0) / 4.0) + 1.0;
}

// The most steps per ray llvmpipe's loop budget allows on a scene of
// `triangles` triangles (exact: exact_edges is on).
static int llvmpipe_max_steps(double triangles, bool exact) {
    if (!exact || triangles <= TOTH_LLVMPIPE_REF_TRIANGLES) return TOTH_LLVMPIPE_MAX_STEPS;
    return (int)(TOTH_LLVMPIPE_MAX_STEPS * bvh_depth(TOTH_LLVMPIPE_REF_TRIANGLES) /
                 bvh_depth(triangles));
}

static double scene_triangles(const st_scene *sc) {
    double n = 0;
    for (int i = 0; i < sc->num_meshes; i++)
        n += sc->meshes[i].num_triangles;
    return n;
}

static bool steps_fit(const toth *t, const st_scene *sc, st_err *err) {
    int m = interleave(t), n = steps(t), per_ray = (n + m * m - 1) / (m * m);
    double tris = scene_triangles(sc);
    int max = llvmpipe_max_steps(tris, t->p[P_EXACT] != 0);
    if (sampling(t, sc) != SAMPLING_EQUIANGULAR || per_ray <= max ||
        !strstr(st_context_renderer(), "llvmpipe"))
        return true;
    if (max < TOTH_LLVMPIPE_MAX_STEPS)
        return st_fail(err, ST_ERR_INPUT,
                       "toth.samples=%d: %d equi-angular steps per ray with exact rays through "
                       "the BVH of scene '%s' (%.0f triangles) exceed llvmpipe's loop budget (at "
                       "most %d per ray on this scene; beyond it Mesa cuts the march short "
                       "without an error); use toth.samples <= %d, toth.interleave, "
                       "toth.exact_edges=false, or a GPU driver",
                       n, per_ray, sc->path, tris, max, max);
    return st_fail(err, ST_ERR_INPUT,
                   "toth.samples=%d: %d equi-angular steps per ray exceed llvmpipe's loop budget "
                   "(at most %d per ray; beyond it Mesa cuts the march short without an error); "
                   "use toth.samples <= %d, toth.interleave, or a GPU driver",
                   n, per_ray, max, max);
}

// The first pass's needed(): re-declares the targets when a new image
// height moves the march divisor (needed() runs for every pass before the
// world binds targets), chooses between drawing and dispatching the march,
// and decides whether this frame reuses the first frame's fractions.
static void begin_frame(toth *t, const st_frame *f, bool any) {
    if (scale(t, f->height) != t->decl_scale) {
        st_err ignore = {0}; // only fails for a bad name, which create already caught
        declare_targets(t, f->height, &ignore);
    }
    // A march of fewer than 4 llvmpipe tiles (64 x 64) is dispatched: drawn,
    // its tiles would leave threads idle (march.comp).
    int s = t->decl_scale, tx = ((f->width + s - 1) / s + 63) / 64,
        ty = ((f->height + s - 1) / s + 63) / 64;
    t->dispatch = tx * ty < 4;
    // reuse=on: a frame whose only change since the march last ran is the
    // box filter's sub-pixel jitter (its gbuffer rewritten by it) reads the
    // fractions the first frame kept; march, gather, edges and keep rest.
    const unsigned jitter_only = ST_CHANGE_CAMERA | ST_CHANGE_JITTER | ST_CHANGE_INPUTS;
    t->reusing = any && reuse_on(t) && t->kept && sampling(t, f->scene) == SAMPLING_EQUIANGULAR &&
                 (f->changes & ST_CHANGE_JITTER) && !(f->changes & ~jitter_only);
    if (!t->reusing) t->kept = false;
}

// Nothing runs without a scattering medium or without lights: toth adds
// in-scattered light only (the regular pass applies the view's extinction).
static bool needed(void *self, int pass, const st_frame *f) {
    toth *t = self;
    bool any = medium_scatters(f->scene) && f->scene->num_lights > 0;
    if (pass == PASS_MARCH) begin_frame(t, f, any);
    if (!any || (t->reusing && pass != PASS_COMPOSE)) return false;
    bool equiangular = sampling(t, f->scene) == SAMPLING_EQUIANGULAR;
    switch (pass) {
    case PASS_GATHER:
        return interleave(t) > 1;
    case PASS_EDGES: // only where compose may read it (below full resolution)
        return equiangular && t->decl_scale > 1 && (t->p[P_REFINE] < 1 || t->p[P_REFINE_KINK] > 0);
    case PASS_KEEP: // only a box-filtered still has jittered frames to keep for
        return reuse_on(t) && equiangular && f->filter == ST_FILTER_BOX;
    default:
        return true;
    }
}

static int program(void *self, int pass, const st_frame *f) {
    (void)f;
    const toth *t = self;
    switch (pass) {
    case PASS_MARCH:
        return t->dispatch ? PROG_MARCH_CS : PROG_MARCH;
    case PASS_GATHER:
        return PROG_GATHER;
    case PASS_EDGES:
        return PROG_EDGES;
    case PASS_KEEP:
        return PROG_KEEP;
    default:
        return t->reusing ? PROG_COMPOSE_REUSE : PROG_COMPOSE;
    }
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

// What the parameters do not say as uniforms of their own name (the world
// sets toth_<param> on every program, param_uniforms): the march divisor,
// the steps (samples=0: see steps()), the interleave as limited by them,
// the names that differ.
static void set_common(toth *t, st_shader *sh) {
    st_shader_set_int(sh, "toth_samples", steps(t));
    st_shader_set_int(sh, "toth_scale", t->decl_scale);
    st_shader_set_float(sh, "toth_tolerance", (float)t->p[P_TOLERANCE]);
    st_shader_set_int(sh, "toth_interleave", interleave(t));
}

// How a ray's visible fraction is marched (toth/visibility.glsl): the march
// pass and the edges pass's march step share it.
static void set_march(toth *t, st_shader *sh) {
    st_shader_set_int(sh, "toth_exact", t->p[P_EXACT] != 0);
    st_shader_set_int(sh, "toth_exact_solve", TOTH_EXACT_SOLVE);
}

// The pass's input at march resolution: the gather's sums, or the march.
static const st_target *inscatter(toth *t) {
    return st_world_target(t->w, interleave(t) > 1 ? "toth.gather" : "toth.march");
}

// The edges pass's select step: toth.refined cleared to -1 (compose then
// upsamples every pixel not marched here); one point per scale x scale
// block (edges.vert keeps those with a pixel that may need its own ray)
// lists the pixels that do (toth/edges_list.glsl: a count, then one entry
// per pixel of the image rounded up to 4 x 4 blocks).
static bool select_edges(toth *t, const st_frame *f, st_err *err) {
    st_shader *sh = f->shader;
    const st_target *src = inscatter(t);
    int s = t->decl_scale, bx = (f->width + s - 1) / s, by = (f->height + s - 1) / s;
    t->grid_w = (f->width + 3) & ~3, t->grid_h = (f->height + 3) & ~3;
    GLuint list = st_world_buffer(t->w, "toth.edges_list",
                                  sizeof(GLuint) * (1 + (size_t)t->grid_w * t->grid_h), NULL, err);
    if (!list) return false;
    if (!src) return st_fail(err, ST_ERR_RUNTIME, "toth: no march target");
    set_common(t, sh);
    st_shader_set_int(sh, "toth_blocks_x", bx);
    st_shader_texture(sh, "toth_inscatter_tex", GL_TEXTURE_2D, src->color[0]);
    const float none[4] = {-1, -1, -1, -1};
    glClearBufferfv(GL_COLOR, 0, none);
    const GLuint zero = 0;
    glClearNamedBufferSubData(list, GL_R32UI, 0, sizeof zero, GL_RED_INTEGER, GL_UNSIGNED_INT,
                              &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, list); // edges_list.glsl's binding
    if (!t->vao) glCreateVertexArrays(1, &t->vao);
    glBindVertexArray(t->vao);
    // Writes only the list (toth.refined keeps the clear).
    glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glPointSize((float)s);
    glDrawArrays(GL_POINTS, 0, bx * by);
    glPointSize(1.0f);
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    return true;
}

// The edges pass's march step: one fragment per listed pixel, packed in
// 4 x 4 blocks (llvmpipe runs 4 x 4 blocks in 8-wide vectors), into the
// framebuffer without attachments, storing the fractions to toth.refined.
// The count stays on the GPU: the vertex shader sizes its quad by it.
static bool march_edges(toth *t, const st_frame *f, st_err *err) {
    const st_target *refined = st_world_target(t->w, "toth.refined");
    if (!refined) return st_fail(err, ST_ERR_RUNTIME, "toth: no refined target");
    if (!t->list_fbo) glCreateFramebuffers(1, &t->list_fbo);
    glNamedFramebufferParameteri(t->list_fbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, t->grid_w);
    glNamedFramebufferParameteri(t->list_fbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, t->grid_h);
    GLint fbo = 0, vp[4];
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fbo);
    glGetIntegerv(GL_VIEWPORT, vp);
    glBindFramebuffer(GL_FRAMEBUFFER, t->list_fbo);
    glViewport(0, 0, t->grid_w, t->grid_h);
    st_shader *m = st_frame_use_program(f, PROG_EDGES_MARCH, err);
    if (!m) return false;
    set_common(t, m);
    st_shader_set_int(m, "toth_edges_width", t->grid_w);
    st_shader_set_int(m, "toth_edges_height", t->grid_h);
    set_march(t, m);
    glBindImageTexture(0, refined->color[0], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT); // compose and keep read toth.refined
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)fbo);
    glViewport(vp[0], vp[1], vp[2], vp[3]);
    return true;
}

// The march, drawn or dispatched by the world into toth.march (march.comp
// says when which).
static bool on_march(toth *t, const st_frame *f, st_err *err) {
    if (!steps_fit(t, f->scene, err)) return false;
    set_common(t, f->shader);
    set_march(t, f->shader);
    st_shader_set_int(f->shader, "toth_sampling", sampling(t, f->scene));
    return true;
}

static bool on_gather(toth *t, const st_frame *f, st_err *err) {
    const st_target *march = st_world_get_target(t->w, "toth.march", err);
    if (!march) return false;
    set_common(t, f->shader);
    st_shader_set_int(f->shader, "toth_sampling", sampling(t, f->scene));
    st_shader_texture(f->shader, "toth_march_tex", GL_TEXTURE_2D, march->color[0]);
    return true;
}

// The world draws the fractions into toth.first; the gbuffer is copied beside them.
static bool on_keep(toth *t, const st_frame *f, st_err *err) {
    const st_target *gb = st_world_get_target(t->w, "toth.first_gbuffer", err);
    if (!gb) return false;
    const st_target *src = inscatter(t), *refined = st_world_target(t->w, "toth.refined");
    set_common(t, f->shader);
    if (!src) return st_fail(err, ST_ERR_RUNTIME, "toth: no march target");
    st_shader_texture(f->shader, "toth_inscatter_tex", GL_TEXTURE_2D, src->color[0]);
    if (refined) st_shader_texture(f->shader, "toth_refined_tex", GL_TEXTURE_2D, refined->color[0]);
    glCopyImageSubData(f->gbuffer, GL_TEXTURE_2D, 0, 0, 0, 0, gb->color[0], GL_TEXTURE_2D, 0, 0, 0,
                       0, f->width, f->height, 1);
    memcpy(t->first_vp, f->view_proj, sizeof t->first_vp);
    t->kept = true;
    return true;
}

// A jittered frame of a still reads the first frame's fractions (reuse.glsl).
static bool bind_first(toth *t, st_shader *sh, st_err *err) {
    const st_target *first = st_world_target(t->w, "toth.first");
    const st_target *gb = st_world_target(t->w, "toth.first_gbuffer");
    if (!first || !gb) return st_fail(err, ST_ERR_RUNTIME, "toth: no kept fractions");
    st_shader_texture(sh, "toth_first_tex", GL_TEXTURE_2D, first->color[0]);
    st_shader_texture(sh, "toth_first_gbuffer", GL_TEXTURE_2D, gb->color[0]);
    st_shader_set_mat4(sh, "toth_first_view_proj", t->first_vp);
    return true;
}

static bool on_compose(toth *t, const st_frame *f, st_err *err) {
    st_shader *sh = f->shader;
    const st_target *src = inscatter(t), *refined = st_world_target(t->w, "toth.refined");
    if (t->reusing && !bind_first(t, sh, err)) return false;
    set_common(t, sh);
    st_shader_set_int(sh, "toth_sampling", sampling(t, f->scene));
    // The kink rule is for the visible fraction (sampling=uniform
    // upsamples in-scattered light).
    if (sampling(t, f->scene) != SAMPLING_EQUIANGULAR)
        st_shader_set_float(sh, "toth_upsample_kink", 0.0f);
    st_shader_set_int(sh, "toth_has_inscatter", src != NULL);
    st_shader_set_float(sh, "toth_glow_radius", TOTH_GLOW_RADIUS_PX);
    if (src) st_shader_texture(sh, "toth_inscatter_tex", GL_TEXTURE_2D, src->color[0]);
    if (refined) st_shader_texture(sh, "toth_refined_tex", GL_TEXTURE_2D, refined->color[0]);
    if (t->p[P_COMPOSE] == COMPOSE_TABLE) {
        GLuint table = airlight_table(t, &f->scene->medium, err);
        if (!table) return false;
        st_shader_texture(sh, "toth_airlight_tex", GL_TEXTURE_2D, table);
    }
    return true;
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    toth *t = self;
    bool ok;
    switch (pass) {
    case PASS_MARCH:
        ok = on_march(t, f, err);
        break;
    case PASS_GATHER:
        ok = on_gather(t, f, err);
        break;
    case PASS_EDGES:
        ok = select_edges(t, f, err) && march_edges(t, f, err);
        break;
    case PASS_KEEP:
        ok = on_keep(t, f, err);
        break;
    default:
        ok = on_compose(t, f, err);
        break;
    }
    return ok && st_gl_check("toth pass", err);
}

// Hot reload (the world recompiles the programs): the next frame marches
// with the new code.
static bool reload(void *self, st_err *err) {
    (void)err;
    ((toth *)self)->kept = false;
    return true;
}

// A new march scale, interleave or reuse re-describes the targets (a new
// compose method recompiles compose, through its param_defines).
static void param_changed(void *self, int index) {
    st_err ignore = {0}; // only fails for a bad name, which create already caught
    if (index == P_RESOLUTION || index == P_INTERLEAVE || index == P_SAMPLES ||
        index == P_MIN_ROWS || index == P_REUSE)
        declare_targets(self, ((toth *)self)->height, &ignore);
}

ST_PLUGIN(.name = "toth",
          .description =
              "single scattering in a homogeneous medium (Toth & Umenhoffer 2009): equi-angular "
              "per-pixel integral times a shadow-mapped visible fraction (or the uniform march), "
              "interleaved sampling, reduced-resolution march",
          ST_PARAMS(params), ST_PROGRAMS(programs), ST_PASSES(passes), .param_uniforms = "toth_",
          .requires = "shadow_map", .provides = ST_CAP_INSCATTER, .create = create,
          .destroy = destroy, .needed = needed, .program = program, .on_pass = on_pass,
          .param_changed = param_changed, .reload = reload, .light_types = ST_LIGHT_BITS_ALL)
