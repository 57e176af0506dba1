// atlas_gi: texture-atlas global illumination (Merz 2010, docs/physics.md).
// The whole scene lives in one atlas (TEXCOORD_1, or generated: atlas.c).
// Pass "gbuffer" rasterizes every triangle at its atlas position (plus one
// point per texel the rasterizer would miss) into a G-buffer atlas: world
// position and area, normal and validity, albedo, direct + emitted radiance
// (with shadow_map's visibility when loaded). Pass "gather" gathers one
// bounce per texel from N Hammersley samples over the atlas, repeats it for
// more bounces, accumulates frames under a Cranley-Patterson rotation until
// the mean converges, and dilates the result into the gutters. The regular
// pass looks the indirect radiance up at each surface point's atlas uv.
//
// Nothing runs that the scene does not need: the atlas is rebuilt only when
// geometry or its parameters change, the G-buffer only when lights (or the
// shadow map) change, the gather only when its inputs or parameters change or
// while accumulation has not converged. A camera-only frame runs neither pass.
//
// This file: the descriptor (parameters, programs, exports) and the hooks,
// which call the other files (agi.h says which holds what; calls run one way).
#include "agi.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const st_param_def params[P_COUNT] = {
    {"atlas_size", ST_PARAM_INT, 512, 64, 4096, NULL,
     "atlas width and height in texels; a generated atlas gets the largest texel density that "
     "fits"},
    {"texels_per_meter", ST_PARAM_FLOAT, 0, 0, 100000, NULL,
     "fixed density of a generated atlas (0: fit atlas_size); the atlas becomes the smallest power "
     "of two >= 64 that holds it"},
    {"samples", ST_PARAM_INT, 100, 1, 4096, NULL,
     "Hammersley samples over the atlas per texel and frame (the thesis' N)"},
    {"estimator", ST_PARAM_ENUM, 0, 0, 1, "area|thesis",
     "area: the design's area-sampling estimator with disk-bounded 1/d^2; thesis: 2 pi/N sum L0 "
     "cos (Merz 2010, eq. 9)"},
    {"sampling", ST_PARAM_ENUM, 1, 0, 1, "uniform|power",
     "area estimator: uniform picks over the atlas (the design), or picks in proportion to each "
     "texel's flux a_j L0_j "
     "(25% in proportion to a_j), weighted by 1/(N p_j): same expectation, far less variance from "
     "small bright spots"},
    {"visibility", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "trace each sample's segment against a BVH of the scene (off: the thesis, light leaks through "
     "walls)"},
    {"bounces", ST_PARAM_INT, 1, 1, 8, NULL,
     "diffuse bounces; each repeats the gather with L0 = direct + previous bounce"},
    {"progressive", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "while nothing changes, accumulate frames with a rotated sample set until the mean converges"},
    {"max_frames", ST_PARAM_INT, 256, 1, 65536, NULL, "accumulate at most this many frames"},
    {"tolerance", ST_PARAM_FLOAT, 0.05, 0, 1, NULL,
     "stop accumulating once the RMS over texels of the standard error of the mean, relative to "
     "the mean indirect "
     "radiance, is below this (0: run max_frames)"},
    {"display", ST_PARAM_ENUM, 0, 0, 3, "combined|direct|indirect|atlas",
     "combined: direct + emission + indirect; direct; indirect only; atlas: the combined atlas "
     "textured back (the thesis' display)"},
    {"chart_angle", ST_PARAM_FLOAT, 30, 1, 89, NULL,
     "generated atlas: largest angle (degrees) between a triangle and its chart's plane"},
    {"mode", ST_PARAM_ENUM, 0, 0, 1, "transfer|gather",
     "transfer: links between texel clusters with form factors and visibility, precomputed once "
     "per atlas on the CPU "
     "(Embree, all cores); a relight is GPU passes without noise, the first frame is converged. "
     "gather: the thesis' "
     "per-frame Hammersley gather, accumulated over frames"},
    {"transfer_leaves", ST_PARAM_INT, 8192, 256, 1048576, NULL,
     "transfer: at most this many leaves in the cluster tree; on larger atlases a leaf groups "
     "neighbouring texels, at most 5% of the scene's size across "
     "(bounds precompute time and memory; a texel still gets its own first-order value)"},
    {"transfer_eps", ST_PARAM_FLOAT, 0.15, 0.002, 0.5, NULL,
     "transfer: refinement tolerance: a link's sender node may subtend at most this A/(pi d^2) "
     "(receivers a quarter of it) and the link's form factor may vary by at most eps/50 over "
     "its texel pairs; smaller is more accurate, with more links and a longer precompute"},
    {"profile", ST_PARAM_BOOL, 0, 0, 1, NULL,
     "transfer: wait for the GPU after every step of a relight and report the steps' median "
     "times in --stats (benchmarks only: the waits slow the relight down)"},
};

// The programs, compiled by the world on first use (a mode's programs only
// when it runs) and hot-reloaded with st_world_reload_shaders.
#define CHUNK "AG_CHUNK " TRG_CHUNK_S
static const st_program_decl programs[PR_COUNT] = {
    [PR_GBUFFER] = {"gbuffer", "atlas_gi/gbuffer.vert", "atlas_gi/gbuffer.frag",
                    .flags = ST_PROGRAM_LIGHTS},
    [PR_GBUFFER_SHADOW] = {"gbuffer_shadow", "atlas_gi/gbuffer.vert", "atlas_gi/gbuffer.frag",
                           .defines = "AG_SHADOW 1", .flags = ST_PROGRAM_LIGHTS},
    [PR_GBUFFER_POINTS] = {"gbuffer_points", "atlas_gi/gbuffer_points.vert",
                           "atlas_gi/gbuffer.frag", .defines = "AG_POINTS 1",
                           .flags = ST_PROGRAM_LIGHTS},
    [PR_GBUFFER_POINTS_SHADOW] = {"gbuffer_points_shadow", "atlas_gi/gbuffer_points.vert",
                                  "atlas_gi/gbuffer.frag", .defines = "AG_SHADOW 1\nAG_POINTS 1",
                                  .flags = ST_PROGRAM_LIGHTS},
    [PR_GBUFFER_L0] = {"gbuffer_l0", "atlas_gi/gbuffer.vert", "atlas_gi/gbuffer.frag",
                       .defines = "AG_L0_ONLY 1", .flags = ST_PROGRAM_LIGHTS},
    [PR_GBUFFER_L0_SHADOW] = {"gbuffer_l0_shadow", "atlas_gi/gbuffer.vert", "atlas_gi/gbuffer.frag",
                              .defines = "AG_L0_ONLY 1\nAG_SHADOW 1", .flags = ST_PROGRAM_LIGHTS},
    [PR_GBUFFER_L0_POINTS] = {"gbuffer_l0_points", "atlas_gi/gbuffer_points.vert",
                              "atlas_gi/gbuffer.frag", .defines = "AG_L0_ONLY 1\nAG_POINTS 1",
                              .flags = ST_PROGRAM_LIGHTS},
    [PR_GBUFFER_L0_POINTS_SHADOW] = {"gbuffer_l0_points_shadow", "atlas_gi/gbuffer_points.vert",
                                     "atlas_gi/gbuffer.frag",
                                     .defines = "AG_L0_ONLY 1\nAG_SHADOW 1\nAG_POINTS 1",
                                     .flags = ST_PROGRAM_LIGHTS},
    [PR_GATHER] = {"gather", .frag = "atlas_gi/gather.frag"},
    [PR_GATHER_VIS] = {"gather_visibility", .frag = "atlas_gi/gather.frag",
                       .defines = "AG_VISIBILITY 1"},
    [PR_RESOLVE] = {"resolve", .frag = "atlas_gi/resolve.frag"},
    [PR_REDUCE] = {"transfer_reduce", .comp = "atlas_gi/transfer_reduce.comp", .defines = CHUNK},
    [PR_LINKS] = {"transfer_links", .comp = "atlas_gi/transfer_gather.comp", .defines = CHUNK},
    [PR_LINKS_MEDIUM] = {"transfer_links_medium", .comp = "atlas_gi/transfer_gather.comp",
                         .defines = CHUNK "\nAG_MEDIUM 1"},
    [PR_SUM] = {"transfer_sum", .comp = "atlas_gi/transfer_sum.comp", .defines = CHUNK},
    [PR_PUSH] = {"transfer_push", .frag = "atlas_gi/transfer_push.frag", .defines = CHUNK},
};

// What the regular pass (regular.glsl) reads: the resolved atlases, the
// triangle table and per-mesh bases (buffer textures), the display choice.
static const st_export_decl exports[] = {
    {"ag_indirect_tex", .target = "atlas_gi.indirect"},
    {"ag_combined_tex", .target = "atlas_gi.combined"},
    {"ag_tri_tex", .target = "atlas_gi.triangles_tex"},
    {"ag_base_tex", .target = "atlas_gi.mesh_base_tex"},
    {"ag_display", .param = "display"},
};

// ---- hooks ------------------------------------------------------------------

static void destroy(void *self) {
    agi *g = self;
    agi_release_transfer(g);
    agi_release_atlas_gpu(g); // the world frees the declared targets
    agi_gather_free(g);
    free(g);
}

// A new atlas (the transfer is built over it, so it goes first).
static bool rebuild_atlas(agi *g, st_err *err) {
    agi_release_transfer(g);
    return agi_build_atlas(g, err);
}

static void *create(st_world *w, const double *p, st_err *err) {
    agi *g = calloc(1, sizeof *g);
    if (!g) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    g->w = w;
    g->TG.w = w;
    g->p = p;
    g->rel_err = INFINITY;
    if (!rebuild_atlas(g, err)) {
        destroy(g);
        return NULL;
    }
    return g;
}

static int num_passes(void *self) {
    return 2;
}

static const st_pass_info *pass_info(void *self, int pass) {
    agi *g = self;
    if (pass == 0)
        g->info[0] = (st_pass_info){"gbuffer", ST_STAGE_PRE, "shadow_map", "atlas_gi.gbuffer", 0};
    else
        g->info[1] = (st_pass_info){"gather", ST_STAGE_PRE, "atlas_gi.gbuffer", "atlas_gi", 0};
    return &g->info[pass];
}

static bool needed(void *self, int pass, const st_frame *f) {
    agi *g = self;
    if (pass == 0) {
        if (st_world_has_module(g->w, "shadow_map") != g->shadow) g->gb_dirty = true;
        // The gather and the atlas display read every texel's L0, and a new
        // transfer may take in texels the last relights did not light.
        if (g->l0_partial && (ip(g, P_MODE) != 0 || ip(g, P_DISPLAY) == 3 || !g->have_transfer))
            g->gb_dirty = true;
        return g->atlas_dirty || g->gb_dirty ||
               (f->changes & (ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY | ST_CHANGE_LIGHTS |
                              ST_CHANGE_INPUTS | ST_CHANGE_MEDIUM | ST_CHANGE_PROGRAMS));
    }
    return g->restart || (f->changes & (ST_CHANGE_FIRST | ST_CHANGE_INPUTS | ST_CHANGE_PROGRAMS)) ||
           !g->converged;
}

// Pass 0: a new atlas where the geometry changed, then the G-buffer (timed
// as the relight's step 0 with profile=true). Pass 1: the mode's gather.
static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    agi *g = self;
    if (pass == 1)
        return ip(g, P_MODE) == 0 ? agi_transfer_pass(g, f, err) : agi_gather_pass(g, f, err);
    memset(g->prof_gb, 0, sizeof g->prof_gb);
    agi_prof_mark(g, NULL, 0);
    if ((f->changes & ST_CHANGE_GEOMETRY) && !(f->changes & ST_CHANGE_FIRST)) g->atlas_dirty = true;
    if (g->atlas_dirty && !rebuild_atlas(g, err)) return false;
    return agi_gbuffer_pass(g, f, err);
}

static void param_changed(void *self, int k) {
    agi *g = self;
    switch (k) {
    case P_ATLAS_SIZE:
    case P_TEXELS_PER_METER:
    case P_CHART_ANGLE:
        g->atlas_dirty = true;
        break;
    case P_VISIBILITY:
    case P_TRANSFER_EPS:
    case P_TRANSFER_LEAVES:
        agi_release_transfer(g);
        g->restart = true;
        g->converged = false;
        break;
    case P_SAMPLES:
    case P_SAMPLING:
    case P_ESTIMATOR:
    case P_MODE:
    case P_BOUNCES:
        g->restart = true;
        g->converged = false;
        break;
    case P_PROGRESSIVE:
    case P_MAX_FRAMES:
    case P_TOLERANCE:
        agi_update_converged(g);
        break;
    default:
        break; // display: the regular pass only (an export)
    }
}

static bool progress(void *self, st_progress *out) {
    agi *g = self;
    out->converged = g->converged;
    out->frames = (uint32_t)g->frames;
    out->error = g->rel_err;
    if (g->have_transfer) agi_relight_info(g, out->info, sizeof out->info);
    return true;
}

// The regular pass' one derived value: whether the atlas uv is the scene's
// uv1 (0) or is found through the triangle table (1).
static void u_lookup(void *self, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, ((agi *)self)->lookup);
}

static const st_uniform uniforms_table[] = {{"ag_lookup", u_lookup}};

static int uniforms(void *self, const st_uniform **out) {
    *out = uniforms_table;
    return 1;
}

ST_PLUGIN(.name = "atlas_gi",
          .description =
              "texture-atlas global illumination (Merz 2010): G-buffer atlas, precomputed "
              "transfer (default) or the thesis' Hammersley gather, visibility, more bounces, "
              "textured back onto the scene",
          ST_PARAMS(params), ST_PROGRAMS(programs), ST_EXPORTS(exports), .requires = "shadow_map?",
          .provides = "atlas_gi", .regular_include = "atlas_gi/regular.glsl", .create = create,
          .destroy = destroy, .num_passes = num_passes, .pass_info = pass_info,
          .uniforms = uniforms, .needed = needed, .on_pass = on_pass,
          .param_changed = param_changed, .progress = progress,
          .light_types = ST_LIGHT_BITS_ALL /* direct light through common/lighting.glsl */)
