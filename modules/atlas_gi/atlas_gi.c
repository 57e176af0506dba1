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
#define _POSIX_C_SOURCE 200809L // clock_gettime (profile)
#include "atlas.h"
#include "st_bvh.h"
#include "transfer.h"
#include "transfer_gpu.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum {
    P_ATLAS_SIZE,
    P_TEXELS_PER_METER,
    P_SAMPLES,
    P_ESTIMATOR,
    P_SAMPLING,
    P_VISIBILITY,
    P_BOUNCES,
    P_PROGRESSIVE,
    P_MAX_FRAMES,
    P_TOLERANCE,
    P_DISPLAY,
    P_CHART_ANGLE,
    P_MODE,
    P_TRANSFER_LEAVES,
    P_TRANSFER_EPS,
    P_PROFILE,
    P_COUNT
};

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

enum {
    T_POS,
    T_NORMAL,
    T_ALBEDO,
    T_L0,
    T_AREA,
    T_BOUNCE0,
    T_BOUNCE1,
    T_ACCUM,
    T_INDIRECT,
    T_COMBINED,
    T_STATS,
    T_COUNT
};

// The atlas' textures, owned by the world (declared in build_atlas).
static const char *const tex_name[T_COUNT] = {
    "atlas_gi.position", "atlas_gi.normal",   "atlas_gi.albedo",  "atlas_gi.direct",
    "atlas_gi.area",     "atlas_gi.bounce0",  "atlas_gi.bounce1", "atlas_gi.accum",
    "atlas_gi.indirect", "atlas_gi.combined", "atlas_gi.stats"};
static const GLenum tex_format[T_COUNT] = {GL_RGBA32F, GL_RGBA32F, GL_RGBA16F, GL_RGBA32F,
                                           GL_R32F,    GL_RGBA32F, GL_RGBA32F, GL_RGBA32F,
                                           GL_RGBA32F, GL_RGBA32F, GL_RGBA32F};
// The buffers it creates itself, tracked by the world for --stats.
static const char *const atlas_buffers[] = {
    "atlas_gi.points",        "atlas_gi.vertices",      "atlas_gi.indices",
    "atlas_gi.triangles",     "atlas_gi.triangles_tex", "atlas_gi.mesh_base",
    "atlas_gi.mesh_base_tex", "atlas_gi.bvh_nodes",     "atlas_gi.bvh_triangles"};
enum { AG_PROF_STEPS = 5, AG_PROF_MAX = 64 };
static const char *const prof_names[AG_PROF_STEPS] = {"G-buffer", "reduce", "links", "push",
                                                      "resolve"};

typedef struct agi {
    st_world *w;
    const double *p;
    atlas A;
    double extent;
    st_bvh B;
    st_bvh_gpu B_gpu;
    bool have_bvh;
    st_mesh *gmeshes; // shallow copies of A.meshes[i].mesh for the model type
    st_model_type type;
    st_model *models;
    int num_models;
    int W, H, stats_top;
    GLuint tex[T_COUNT];
    GLuint fbo_gb, fbo_gather[2], fbo_resolve;
    GLuint ham_tex;
    int ham_n;
    float *ham; // the Hammersley points on the CPU (power sampling)
    // Power sampling: the per-texel probabilities and their CDFs (rows, then
    // columns within a row), built from the G-buffer's L0 and the areas.
    float *pmf;
    double *cdf_row, *cdf;
    bool have_cdf;
    GLuint pick_tex; // N picks: texel x, y, 1/(N p)
    int pick_cap;
    float *picks;
    GLuint pts_vao, pts_vbo;
    int num_points;
    GLuint tri_buf, tri_tex, base_buf, base_tex;
    int lookup; // 0: uv1, 1: triangle table
    st_shader *sh_gb, *sh_gbp, *sh_gather, *sh_gather_vis, *sh_resolve;
    // Precomputed transfer (mode=transfer), built on first use per atlas.
    transfer T;
    bool have_transfer;
    tr_gpu TG; // its GPU copy and the relight's shaders
    // profile=true: per relight step (prof_names) the last
    // AG_PROF_MAX wall and process CPU times in ms, and when the current
    // step began (CPU time: llvmpipe's work, less inflated by other
    // processes on a shared machine than the wall time).
    float prof[2][AG_PROF_STEPS][AG_PROF_MAX];
    int prof_n;
    double prof_t[2];
    double prof_gb[2][AG_PROF_STEPS]; // the G-buffer pass of this relight (step 0)
    bool shadow;
    bool atlas_dirty, gb_dirty, restart;
    int frames;
    bool converged;
    double rel_err;
    st_pass_info info[2];
} agi;

static int ip(const agi *g, int k) {
    return (int)g->p[k];
}

// ---- resources ----------------------------------------------------------------

static void release_transfer(agi *g) {
    tr_gpu_release(&g->TG);
    transfer_free(&g->T);
    g->have_transfer = false;
}

static void release_atlas_gpu(agi *g) {
    for (int i = 0; i < T_COUNT; i++) // fresh textures for the next atlas, as before
        st_world_declare_target(g->w, tex_name[i], NULL, &(st_err){0});
    memset(g->tex, 0, sizeof g->tex);
    for (size_t i = 0; i < sizeof atlas_buffers / sizeof atlas_buffers[0]; i++)
        st_world_untrack(g->w, atlas_buffers[i]);
    GLuint fbos[4] = {g->fbo_gb, g->fbo_gather[0], g->fbo_gather[1], g->fbo_resolve};
    glDeleteFramebuffers(4, fbos);
    g->fbo_gb = g->fbo_gather[0] = g->fbo_gather[1] = g->fbo_resolve = 0;
    if (g->pts_vao) glDeleteVertexArrays(1, &g->pts_vao);
    GLuint bufs[3] = {g->pts_vbo, g->tri_buf, g->base_buf};
    glDeleteBuffers(3, bufs);
    st_bvh_gpu_free(&g->B_gpu);
    GLuint texs[2] = {g->tri_tex, g->base_tex};
    glDeleteTextures(2, texs);
    g->pts_vao = g->pts_vbo = g->tri_buf = g->base_buf = g->tri_tex = g->base_tex = 0;
    if (g->type.vao) st_model_type_destroy(&g->type);
    free(g->models);
    free(g->gmeshes);
    g->models = NULL;
    g->gmeshes = NULL;
    g->num_models = 0;
    st_bvh_free(&g->B);
    g->have_bvh = false;
    release_transfer(g);
    atlas_free(&g->A);
}

static GLuint make_fbo(const GLuint *tex, int n) {
    GLuint f;
    GLenum bufs[4];
    glCreateFramebuffers(1, &f);
    for (int i = 0; i < n; i++) {
        glNamedFramebufferTexture(f, GL_COLOR_ATTACHMENT0 + i, tex[i], 0);
        bufs[i] = GL_COLOR_ATTACHMENT0 + i;
    }
    glNamedFramebufferDrawBuffers(f, n, bufs);
    return f;
}

// Builds the atlas on the CPU and everything on the GPU that depends on it.
static bool build_atlas(agi *g, st_err *err) {
    release_atlas_gpu(g);
    const st_scene *sc = st_world_scene(g->w);
    atlas_opts o = {
        .size = ip(g, P_ATLAS_SIZE),
        .texels_per_meter = g->p[P_TEXELS_PER_METER],
        .max_size = 4096,
        .gutter = 2,
        .chart_angle_deg = g->p[P_CHART_ANGLE],
        .use_uv1 = atlas_meshes_have_uv1(sc->meshes, sc->num_meshes),
    };
    if (!atlas_build(&g->A, sc->meshes, sc->num_meshes, &o, err)) return false;
    atlas *A = &g->A;
    int W = g->W = A->width, H = g->H = A->height;
    // The transfer's CPU side holds ~70 bytes per texel.
    if (ip(g, P_MODE) == 0 && (long)W * H > 2048L * 2048L)
        return st_fail(err, ST_ERR_INPUT,
                       "atlas_gi.atlas_size: a %dx%d atlas is too large for mode=transfer (at most "
                       "2048x2048; use "
                       "mode=gather or a smaller atlas)",
                       W, H);
    g->lookup = o.use_uv1 ? 0 : 1;
    // Scene extent, for the visibility rays' offset.
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t k = 0; k < A->num_tris; k++)
        for (int r = 0; r < 3; r++) {
            const float *t = A->tris + 16 * (size_t)k;
            float v[3] = {t[r], t[r] + t[4 + r], t[r] + t[8 + r]};
            for (int c = 0; c < 3; c++)
                lo[r] = fminf(lo[r], v[c]), hi[r] = fmaxf(hi[r], v[c]);
        }
    g->extent = 0;
    for (int r = 0; r < 3 && A->num_tris; r++)
        g->extent = fmax(g->extent, hi[r] - lo[r]);

    // The G-buffer pass draws the split meshes as a model type of their own.
    g->num_models = A->num_meshes;
    g->gmeshes = calloc(A->num_meshes ? (size_t)A->num_meshes : 1, sizeof *g->gmeshes);
    g->models = calloc(A->num_meshes ? (size_t)A->num_meshes : 1, sizeof *g->models);
    if (!g->gmeshes || !g->models) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int i = 0; i < A->num_meshes; i++)
        g->gmeshes[i] = A->meshes[i].mesh;
    if (!st_model_type_build(&g->type, "atlas_gi", g->gmeshes, A->num_meshes, NULL, g->models, err))
        return false;

    g->stats_top = 0;
    while ((W > H ? W : H) >> (g->stats_top + 1))
        g->stats_top++;
    // Texel-exact lookups everywhere but in the two the regular pass filters;
    // the statistics' mip chain averages down to one texel.
    for (int i = 0; i < T_COUNT; i++) {
        bool linear = i == T_INDIRECT || i == T_COMBINED;
        st_target_desc d = {tex_format[i], .width = W, .height = H,
                            .levels = i == T_STATS ? g->stats_top + 1 : 1,
                            .filter = linear ? GL_LINEAR : GL_NEAREST};
        const st_target *t = st_world_alloc_target(g->w, tex_name[i], &d, err);
        if (!t) return false;
        g->tex[i] = t->color[0];
    }
    glTextureSubImage2D(g->tex[T_AREA], 0, 0, 0, W, H, GL_RED, GL_FLOAT, A->area);
    const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(g->tex[T_INDIRECT], 0, GL_RGBA, GL_FLOAT, zero);
    glClearTexImage(g->tex[T_COMBINED], 0, GL_RGBA, GL_FLOAT, zero);
    g->fbo_gb = make_fbo(&g->tex[T_POS], 4);
    g->fbo_gather[0] = make_fbo((GLuint[]){g->tex[T_BOUNCE0], g->tex[T_ACCUM]}, 2);
    g->fbo_gather[1] = make_fbo((GLuint[]){g->tex[T_BOUNCE1], g->tex[T_ACCUM]}, 2);
    g->fbo_resolve = make_fbo(&g->tex[T_INDIRECT], 3);

    // Conservative coverage: points for texels the rasterizer misses.
    g->num_points = A->num_points;
    float *pv = malloc((A->num_points ? (size_t)A->num_points : 1) * 14 * sizeof *pv);
    if (!pv) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int i = 0; i < A->num_points; i++) {
        const atlas_point *pt = &A->points[i];
        const st_mesh *m = &A->meshes[pt->amesh].mesh;
        float *v = pv + 14 * (size_t)i;
        v[0] = (float)pt->x, v[1] = (float)pt->y;
        memcpy(v + 2, pt->pos, 12);
        memcpy(v + 5, pt->nrm, 12);
        memcpy(v + 8, m->albedo, 12);
        memcpy(v + 11, m->emission, 12);
    }
    glCreateBuffers(1, &g->pts_vbo);
    glNamedBufferStorage(
        g->pts_vbo, (GLsizeiptr)((A->num_points ? A->num_points : 1) * 14 * sizeof(float)), pv, 0);
    free(pv);
    glCreateVertexArrays(1, &g->pts_vao);
    glVertexArrayVertexBuffer(g->pts_vao, 0, g->pts_vbo, 0, 14 * sizeof(float));
    const int comps[5] = {2, 3, 3, 3, 3}, offs[5] = {0, 2, 5, 8, 11};
    for (GLuint a = 0; a < 5; a++) {
        glEnableVertexArrayAttrib(g->pts_vao, a);
        glVertexArrayAttribFormat(g->pts_vao, a, comps[a], GL_FLOAT, GL_FALSE,
                                  (GLuint)(offs[a] * sizeof(float)));
        glVertexArrayAttribBinding(g->pts_vao, a, 0);
    }

    // The regular pass' triangle table.
    GLint max_tbo = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_tbo);
    if ((uint64_t)A->num_tris * 3 > (uint64_t)max_tbo)
        return st_fail(err, ST_ERR_RUNTIME,
                       "%u triangles exceed the GPU's texture buffer limit (%d texels)",
                       A->num_tris, max_tbo);
    glCreateBuffers(1, &g->tri_buf);
    glNamedBufferStorage(g->tri_buf,
                         (GLsizeiptr)((A->num_tris ? A->num_tris : 1) * 12 * sizeof(float)),
                         A->lookup, 0);
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &g->tri_tex);
    glTextureBuffer(g->tri_tex, GL_RGBA32F, g->tri_buf);
    int nm = sc->num_meshes ? sc->num_meshes : 1;
    int32_t *base = malloc((size_t)nm * 2 * sizeof *base);
    if (!base) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int i = 0; i < 2 * nm; i++)
        base[i] = sc->num_meshes ? A->mesh_base[i] : -1;
    glCreateBuffers(1, &g->base_buf);
    glNamedBufferStorage(g->base_buf, (GLsizeiptr)(nm * 2 * sizeof *base), base, 0);
    free(base);
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &g->base_tex);
    glTextureBuffer(g->base_tex, GL_RG32I, g->base_buf);
    const GLuint objs[7] = {g->pts_vbo, g->type.vbo.id, g->type.ibo.id, g->tri_buf,
                            g->tri_tex, g->base_buf,    g->base_tex};
    for (int i = 0; i < 7; i++) // 4 and 6: buffer textures over 3 and 5
        if (!st_world_track(g->w, atlas_buffers[i], i == 4 || i == 6 ? GL_TEXTURE : GL_BUFFER,
                            objs[i], err))
            return false;
    g->atlas_dirty = false;
    g->gb_dirty = true;
    return st_gl_check("atlas_gi atlas", err);
}

// Every front-side world triangle once, 9 floats each (visibility).
static float *scene_triangles(const agi *g, uint32_t *count, st_err *err) {
    const atlas *A = &g->A;
    uint32_t n = 0;
    for (int i = 0; i < A->num_meshes; i++)
        if (!A->meshes[i].back) n += A->meshes[i].mesh.num_triangles;
    float *c = malloc((n ? n : 1) * 9 * sizeof *c);
    if (!c) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    uint32_t k = 0;
    for (int i = 0; i < A->num_meshes; i++) {
        if (A->meshes[i].back) continue;
        for (uint32_t t = 0; t < A->meshes[i].mesh.num_triangles; t++, k++) {
            const float *s = A->tris + 16 * (size_t)(A->meshes[i].first_tri + t);
            for (int r = 0; r < 3; r++) {
                c[9 * k + r] = s[r];
                c[9 * k + 3 + r] = s[r] + s[4 + r];
                c[9 * k + 6 + r] = s[r] + s[8 + r];
            }
        }
    }
    *count = n;
    return c;
}

// The BVH for visibility, built on first use over every scene triangle once.
static bool ensure_bvh(agi *g, st_err *err) {
    if (g->have_bvh) return true;
    uint32_t n = 0;
    float *c = scene_triangles(g, &n, err);
    if (!c) return false;
    bool ok = st_bvh_build(&g->B, c, n, err);
    free(c);
    if (!ok || !st_bvh_upload(&g->B_gpu, &g->B, err)) return false;
    if (!st_world_track(g->w, atlas_buffers[7], GL_BUFFER, g->B_gpu.nodes, err) ||
        !st_world_track(g->w, atlas_buffers[8], GL_BUFFER, g->B_gpu.tris, err))
        return false;
    g->have_bvh = true;
    return true;
}

// The precomputed transfer, built on first use per atlas from the G-buffer's
// texel positions and normals (read back once) and uploaded for the relight
// passes.
static bool ensure_transfer(agi *g, st_err *err) {
    if (g->have_transfer) return true;
    size_t cells = (size_t)g->W * g->H;
    float *pos = malloc(cells * 4 * sizeof *pos), *nrm = malloc(cells * 4 * sizeof *nrm);
    uint32_t ntri = 0;
    float *tris = pos && nrm ? scene_triangles(g, &ntri, err) : NULL;
    if (!tris) {
        free(pos);
        free(nrm);
        return pos && nrm ? false : st_fail(err, ST_ERR_RUNTIME, "out of memory");
    }
    glGetTextureImage(g->tex[T_POS], 0, GL_RGBA, GL_FLOAT, (GLsizei)(cells * 4 * sizeof *pos), pos);
    glGetTextureImage(g->tex[T_NORMAL], 0, GL_RGBA, GL_FLOAT, (GLsizei)(cells * 4 * sizeof *nrm),
                      nrm);
    tr_opts o = {
        .eps = g->p[P_TRANSFER_EPS],
        .recv = 0.25,
        .near_k = 2.0,
        .cone_deg = 20.0,
        .samples = 4,
        .kernel = 16,
        .spread = g->p[P_TRANSFER_EPS] / 50,
        .min_split = 4,
        .leaf_size = 0.05,
        .offset = 1e-4 * g->extent,
        .visibility = ip(g, P_VISIBILITY) != 0,
        .max_leaves = ip(g, P_TRANSFER_LEAVES),
    };
    bool ok = transfer_build(&g->T, g->W, g->H, pos, nrm, tris, ntri, &o, err);
    free(pos);
    free(nrm);
    free(tris);
    if (!ok) return false;
    if (!tr_gpu_upload(&g->TG, &g->T, err)) return false;
    g->have_transfer = true;
    return true;
}

// The sample texture (thesis 4.5): X_i = (i/N, radical inverse base 2 of i).
static void ensure_hammersley(agi *g) {
    int n = ip(g, P_SAMPLES);
    if (g->ham_n == n && g->ham_tex) return;
    float *v = realloc(g->ham, (size_t)n * 2 * sizeof *v);
    if (!v) return;
    g->ham = v;
    const st_target_desc d = {GL_RG32F, .type = GL_TEXTURE_1D, .width = n, .filter = GL_NEAREST};
    st_err ignore = {0};
    const st_target *t = st_world_alloc_target(g->w, "atlas_gi.hammersley", &d, &ignore);
    if (!t) return;
    g->ham_tex = t->color[0];
    st_hammersley_upload(g->ham_tex, n, v);
    g->ham_n = n;
}

// Power sampling: p_j = 3/4 a_j Y(L0_j) / sum + 1/4 a_j / sum a (the area part
// keeps every surface texel reachable, which later bounces need), from the
// G-buffer's L0 read back once per G-buffer.
static bool build_cdf(agi *g, st_err *err) {
    size_t n = (size_t)g->W * g->H;
    float *l0 = malloc(n * 4 * sizeof *l0), *pmf = realloc(g->pmf, n * sizeof *pmf);
    if (pmf) g->pmf = pmf;
    double *cdf = pmf ? realloc(g->cdf, n * sizeof *cdf) : NULL;
    if (cdf) g->cdf = cdf;
    double *rows = cdf ? realloc(g->cdf_row, ((size_t)g->H + 1) * sizeof *rows) : NULL;
    if (rows) g->cdf_row = rows;
    if (!l0 || !rows) {
        free(l0);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for the sampling distribution");
    }
    glGetTextureImage(g->tex[T_L0], 0, GL_RGBA, GL_FLOAT, (GLsizei)(n * 4 * sizeof *l0), l0);
    double sf = 0, sa = 0;
    for (size_t j = 0; j < n; j++) {
        double a = g->A.area[j],
               y = 0.2126 * l0[4 * j] + 0.7152 * l0[4 * j + 1] + 0.0722 * l0[4 * j + 2];
        sf += a * fmax(y, 0);
        sa += a;
    }
    rows[0] = 0;
    for (int y = 0; y < g->H; y++) {
        double acc = 0;
        for (int x = 0; x < g->W; x++) {
            size_t j = (size_t)y * g->W + x;
            double a = g->A.area[j],
                   lum = 0.2126 * l0[4 * j] + 0.7152 * l0[4 * j + 1] + 0.0722 * l0[4 * j + 2];
            double w =
                sa > 0 ? (sf > 0 ? 0.75 * a * fmax(lum, 0) / sf + 0.25 * a / sa : a / sa) : 0;
            pmf[j] = (float)w;
            acc += pmf[j];
            cdf[j] = acc;
        }
        rows[y + 1] = rows[y] + acc;
    }
    free(l0);
    g->have_cdf = rows[g->H] > 0;
    return st_gl_check("atlas_gi sampling distribution", err);
}

// The first index in v[0, n) whose value exceeds t (v non-decreasing).
static int upper(const double *v, int n, double t) {
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (v[mid] > t)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

// N picks by inverting the CDF at the rotated Hammersley points: texel x, y
// and 1/(N p); uploaded for the gather.
static bool upload_picks(agi *g, const float *rot, st_err *err) {
    int n = g->ham_n;
    if (g->pick_cap < n) {
        float *p = realloc(g->picks, (size_t)n * 4 * sizeof *p);
        if (!p) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
        g->picks = p;
        const st_target_desc d = {GL_RGBA32F, .type = GL_TEXTURE_1D, .width = n,
                                  .filter = GL_NEAREST};
        const st_target *t = st_world_alloc_target(g->w, "atlas_gi.picks", &d, err);
        if (!t) return false;
        g->pick_tex = t->color[0];
        g->pick_cap = n;
    }
    double total = g->cdf_row[g->H];
    for (int i = 0; i < n; i++) {
        double u = fmod(g->ham[2 * i] + rot[0], 1.0), v = fmod(g->ham[2 * i + 1] + rot[1], 1.0);
        int y = upper(g->cdf_row + 1, g->H, v * total);
        const double *c = g->cdf + (size_t)y * g->W;
        int x = upper(c, g->W, u * c[g->W - 1]); // the row's own sum: no rounding past its end
        double p = g->pmf[(size_t)y * g->W + x] / total;
        float *o = g->picks + 4 * (size_t)i;
        o[0] = (float)x, o[1] = (float)y, o[2] = p > 0 ? (float)(1.0 / (n * p)) : 0.0f, o[3] = 0;
    }
    glTextureSubImage1D(g->pick_tex, 0, 0, n, GL_RGBA, GL_FLOAT, g->picks);
    return st_gl_check("atlas_gi picks", err);
}

static bool compile_gbuffer(agi *g, bool shadow, st_err *err) {
    char defs[256];
    snprintf(defs, sizeof defs, "%s%s", st_world_light_defines(g->w),
             shadow ? "AG_SHADOW 1\n" : "");
    st_shader *a = st_shader_load("atlas_gi/gbuffer.vert", "atlas_gi/gbuffer.frag", defs, err);
    if (!a) return false;
    size_t l = strlen(defs);
    snprintf(defs + l, sizeof defs - l, "AG_POINTS 1\n");
    st_shader *b =
        st_shader_load("atlas_gi/gbuffer_points.vert", "atlas_gi/gbuffer.frag", defs, err);
    if (!b) {
        st_shader_destroy(a);
        return false;
    }
    st_shader_destroy(g->sh_gb);
    st_shader_destroy(g->sh_gbp);
    g->sh_gb = a;
    g->sh_gbp = b;
    g->shadow = shadow;
    return true;
}

// ---- convergence ------------------------------------------------------------

static void update_converged(agi *g) {
    if (ip(g, P_MODE) == 0)
        g->converged = g->frames >= 1; // transfer: deterministic
    else if (!ip(g, P_PROGRESSIVE))
        g->converged = g->frames >= 1;
    else if (g->frames >= ip(g, P_MAX_FRAMES))
        g->converged = true;
    else
        g->converged = g->frames >= 4 && g->rel_err <= g->p[P_TOLERANCE];
}

// ---- hooks ------------------------------------------------------------------

static void destroy(void *self) {
    agi *g = self;
    release_atlas_gpu(g); // the world frees the declared targets
    free(g->ham);
    free(g->picks);
    free(g->pmf);
    free(g->cdf);
    free(g->cdf_row);
    st_shader_destroy(g->sh_gb);
    st_shader_destroy(g->sh_gbp);
    st_shader_destroy(g->sh_gather);
    st_shader_destroy(g->sh_gather_vis);
    st_shader_destroy(g->sh_resolve);
    tr_gpu_destroy(&g->TG);
    free(g);
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
    bool ok = compile_gbuffer(g, st_world_has_module(w, "shadow_map"), err) &&
              (g->sh_gather =
                   st_shader_load("common/fullscreen.vert", "atlas_gi/gather.frag", NULL, err)) &&
              (g->sh_gather_vis = st_shader_load("common/fullscreen.vert", "atlas_gi/gather.frag",
                                                 "AG_VISIBILITY 1\n", err)) &&
              (g->sh_resolve =
                   st_shader_load("common/fullscreen.vert", "atlas_gi/resolve.frag", NULL, err)) &&
              tr_gpu_load_shaders(&g->TG, err) && build_atlas(g, err);
    if (!ok) {
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
        return g->atlas_dirty || g->gb_dirty ||
               (f->changes & (ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY | ST_CHANGE_LIGHTS |
                              ST_CHANGE_INPUTS | ST_CHANGE_MEDIUM));
    }
    return g->restart || (f->changes & (ST_CHANGE_FIRST | ST_CHANGE_INPUTS)) || !g->converged;
}

static void prof_mark(agi *g, double (*acc)[AG_PROF_STEPS], int step);

static bool gbuffer_pass(agi *g, const st_frame *f, st_err *err) {
    memset(g->prof_gb, 0, sizeof g->prof_gb);
    prof_mark(g, NULL, 0);
    if ((f->changes & ST_CHANGE_GEOMETRY) && !(f->changes & ST_CHANGE_FIRST)) g->atlas_dirty = true;
    if (g->atlas_dirty && !build_atlas(g, err)) return false;
    bool shadow = st_world_has_module(g->w, "shadow_map");
    if (shadow != g->shadow && !compile_gbuffer(g, shadow, err)) return false;
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_gb);
    glViewport(0, 0, g->W, g->H);
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < 4; i++)
        glClearBufferfv(GL_COLOR, i, zero);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    // Points first: triangles overwrite wherever their rasterizer reaches.
    st_shader_use(g->sh_gbp);
    st_world_apply_uniforms(g->w, g->sh_gbp, f);
    st_shader_texture(g->sh_gbp, "ag_area_tex", GL_TEXTURE_2D, g->tex[T_AREA]);
    st_shader_set_vec2(g->sh_gbp, "ag_size", (float)g->W, (float)g->H);
    if (g->num_points) {
        glBindVertexArray(g->pts_vao);
        glDrawArrays(GL_POINTS, 0, g->num_points);
    }
    st_shader_use(g->sh_gb);
    st_world_apply_uniforms(g->w, g->sh_gb, f);
    st_shader_texture(g->sh_gb, "ag_area_tex", GL_TEXTURE_2D, g->tex[T_AREA]);
    st_model_type_draw(&g->type, g->models, g->num_models, g->sh_gb);
    prof_mark(g, g->prof_gb, 0);
    g->gb_dirty = false;
    g->have_cdf = false;
    g->restart = true;
    return st_gl_check("atlas_gi G-buffer", err);
}

// The R2 sequence: a well-spread rotation per (frame, bounce), 0 at first.
static void rotation(int index, float *r) {
    r[0] = (float)fmod(index * 0.7548776662466927, 1.0);
    r[1] = (float)fmod(index * 0.5698402909980532, 1.0);
}

// Resolve: mean (accumulated sum / frames), combined atlas, dilation, statistics.
static void resolve(agi *g) {
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_resolve);
    glViewport(0, 0, g->W, g->H);
    st_shader_use(g->sh_resolve);
    st_shader_texture(g->sh_resolve, "ag_pos", GL_TEXTURE_2D, g->tex[T_POS]);
    st_shader_texture(g->sh_resolve, "ag_l0", GL_TEXTURE_2D, g->tex[T_L0]);
    st_shader_texture(g->sh_resolve, "ag_accum", GL_TEXTURE_2D, g->tex[T_ACCUM]);
    st_shader_set_float(g->sh_resolve, "ag_frames", (float)g->frames);
    st_draw_fullscreen();
}

// profile=true: waits for the GPU and adds the time since the last mark to
// acc[wall, CPU][step] (NULL: only starts the clock). Without profile:
// nothing, no wait.
static void prof_mark(agi *g, double (*acc)[AG_PROF_STEPS], int step) {
    if (!ip(g, P_PROFILE)) return;
    glFinish();
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    double t[2] = {st_now_ms(), ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6};
    for (int i = 0; i < 2; i++) {
        if (acc) acc[i][step] += t[i] - g->prof_t[i];
        g->prof_t[i] = t[i];
    }
}

// mode=transfer: every bounce is a reduction up the cluster tree, one pass
// over the links and a push down to the texels. Deterministic: one frame.
typedef struct {
    agi *g;
    const st_frame *f;
} links_ctx;

static void links_setup(void *ctx, st_shader *sh) {
    const links_ctx *c = ctx;
    st_world_apply_uniforms(c->g->w, sh, c->f); // the medium
}

static bool transfer_pass(agi *g, const st_frame *f, st_err *err) {
    if (!ensure_transfer(g, err)) return false;
    const transfer *T = &g->T;
    // No clear of the accumulation: the last bounce's push writes every texel.
    if (!T->num_nodes) {
        const float zero[4] = {0, 0, 0, 0};
        glClearTexImage(g->tex[T_ACCUM], 0, GL_RGBA, GL_FLOAT, zero);
    }
    glViewport(0, 0, g->W, g->H);
    glDisable(GL_DEPTH_TEST);
    double ms[2][AG_PROF_STEPS] = {{g->prof_gb[0][0]}, {g->prof_gb[1][0]}};
    memset(g->prof_gb, 0, sizeof g->prof_gb);
    prof_mark(g, NULL, 0);
    int bounces = ip(g, P_BOUNCES);
    links_ctx lc = {g, f};
    for (int b = 0; b < bounces && T->num_nodes; b++) {
        bool last = b == bounces - 1;
        tr_gpu_reduce(&g->TG, T, g->tex[T_L0], g->tex[b & 1 ? T_BOUNCE0 : T_BOUNCE1], b > 0,
                      g->tex[T_AREA]);
        prof_mark(g, ms, 1);
        tr_gpu_links(&g->TG, f->scene->medium.present, links_setup, &lc);
        prof_mark(g, ms, 2);
        GLuint fbo = g->fbo_gather[b & 1];
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, last ? GL_COLOR_ATTACHMENT1 : GL_NONE};
        glNamedFramebufferDrawBuffers(fbo, 2, bufs);
        glDisablei(GL_BLEND, 0);
        glDisablei(GL_BLEND, 1);
        tr_gpu_push(&g->TG, g->tex[T_ALBEDO], g->tex[T_POS]);
        prof_mark(g, ms, 3);
    }
    for (int i = 0; i < TRG_COUNT; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, 0);
    g->frames = 1;
    g->restart = false;
    resolve(g);
    prof_mark(g, ms, 4);
    if (ip(g, P_PROFILE)) {
        int k = g->prof_n % AG_PROF_MAX;
        for (int c = 0; c < 2; c++)
            for (int i = 0; i < AG_PROF_STEPS; i++)
                g->prof[c][i][k] = (float)ms[c][i];
        g->prof_n++;
    }
    g->rel_err = 0;
    g->converged = true;
    return st_gl_check("atlas_gi transfer", err);
}

static bool gather_pass(agi *g, const st_frame *f, st_err *err) {
    if (ip(g, P_MODE) == 0) return transfer_pass(g, f, err);
    ensure_hammersley(g);
    bool vis = ip(g, P_VISIBILITY) != 0;
    if (vis && !ensure_bvh(g, err)) return false;
    if (g->restart || (f->changes & (ST_CHANGE_FIRST | ST_CHANGE_INPUTS))) {
        g->frames = 0;
        g->rel_err = INFINITY;
        const float zero[4] = {0, 0, 0, 0};
        glClearTexImage(g->tex[T_ACCUM], 0, GL_RGBA, GL_FLOAT, zero);
        g->restart = false;
    }
    glViewport(0, 0, g->W, g->H);
    glDisable(GL_DEPTH_TEST);
    st_shader *sh = vis ? g->sh_gather_vis : g->sh_gather;
    int bounces = ip(g, P_BOUNCES);
    // The thesis estimator is defined for uniform picks only.
    bool power = ip(g, P_SAMPLING) == 1 && ip(g, P_ESTIMATOR) == 0;
    if (power && !g->have_cdf && !build_cdf(g, err)) return false;
    power = power && g->have_cdf;
    if (vis) st_bvh_bind(&g->B_gpu);
    for (int b = 0; b < bounces; b++) {
        bool last = b == bounces - 1;
        GLuint fbo = g->fbo_gather[b & 1];
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, last ? GL_COLOR_ATTACHMENT1 : GL_NONE};
        glNamedFramebufferDrawBuffers(fbo, 2, bufs);
        // The last bounce adds its estimate to the running sums.
        glDisablei(GL_BLEND, 0);
        if (last) {
            glEnablei(GL_BLEND, 1);
            glBlendFunci(1, GL_ONE, GL_ONE);
            glBlendEquationi(1, GL_FUNC_ADD);
        }
        float rot[2];
        rotation(ip(g, P_PROGRESSIVE) ? g->frames * 8 + b : b, rot);
        if (power && !upload_picks(g, rot, err)) return false;
        st_shader_use(sh);
        st_world_apply_uniforms(g->w, sh, f); // the medium's extinction per segment
        st_shader_texture(sh, "ag_pos", GL_TEXTURE_2D, g->tex[T_POS]);
        st_shader_texture(sh, "ag_normal", GL_TEXTURE_2D, g->tex[T_NORMAL]);
        st_shader_texture(sh, "ag_albedo", GL_TEXTURE_2D, g->tex[T_ALBEDO]);
        st_shader_texture(sh, "ag_l0", GL_TEXTURE_2D, g->tex[T_L0]);
        st_shader_texture(sh, "ag_prev", GL_TEXTURE_2D, g->tex[b & 1 ? T_BOUNCE0 : T_BOUNCE1]);
        st_shader_texture(sh, "ag_hammersley", GL_TEXTURE_1D, g->ham_tex);
        st_shader_texture(sh, "ag_picks", GL_TEXTURE_1D, power ? g->pick_tex : g->ham_tex);
        st_shader_set_int(sh, "ag_power", power);
        st_shader_set_int(sh, "ag_use_prev", b > 0);
        st_shader_set_int(sh, "ag_samples", g->ham_n);
        st_shader_set_int(sh, "ag_estimator", ip(g, P_ESTIMATOR));
        st_shader_set_vec2(sh, "ag_rotation", rot[0], rot[1]);
        st_shader_set_float(sh, "ag_offset", (float)(1e-4 * g->extent));
        st_draw_fullscreen();
        glDisablei(GL_BLEND, 1);
    }
    g->frames++;
    resolve(g);
    if (ip(g, P_PROGRESSIVE) && g->frames >= 4 && g->frames < ip(g, P_MAX_FRAMES)) {
        // Relative standard error of the mean over the valid texels, from the
        // 1x1 mip level of the statistics (one small read back per frame).
        glGenerateTextureMipmap(g->tex[T_STATS]);
        float s[4] = {0, 0, 0, 0};
        glGetTextureImage(g->tex[T_STATS], g->stats_top, GL_RGBA, GL_FLOAT, sizeof s, s);
        g->rel_err = s[0] > 0 ? sqrt(fmax(s[1], 0) * fmax(s[2], 0)) / s[0] : 0;
        if (!isfinite(g->rel_err)) g->rel_err = INFINITY;
    }
    update_converged(g);
    return st_gl_check("atlas_gi gather", err);
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    return pass == 0 ? gbuffer_pass(self, f, err) : gather_pass(self, f, err);
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
        release_transfer(g);
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
        update_converged(g);
        break;
    default:
        break; // display: the regular pass only
    }
}

static bool reload(void *self, st_err *err) {
    agi *g = self;
    st_shader *all[5] = {g->sh_gb, g->sh_gbp, g->sh_gather, g->sh_gather_vis, g->sh_resolve};
    for (int i = 0; i < 5; i++)
        if (!st_shader_reload(all[i], err)) return false;
    if (!tr_gpu_reload_shaders(&g->TG, err)) return false;
    g->gb_dirty = true;
    return true;
}

static bool progress(void *self, st_progress *out) {
    agi *g = self;
    out->converged = g->converged;
    out->frames = (uint32_t)g->frames;
    out->error = g->rel_err;
    if (!g->have_transfer) return true;
    const transfer *T = &g->T;
    uint32_t texels = T->num_nodes ? T->nodes[0].end : 0;
    const double mib = 1048576.0;
    int n = snprintf(
        out->info, sizeof out->info,
        "transfer precompute %.2f s (CPU %.2f s) on %d threads, %u texels, %d nodes (<= %d "
        "texels per leaf, %u buried, %u sealed), %llu links, %llu rays, %.1f MiB; GPU %.1f MiB "
        "(nodes %.1f, "
        "links %.1f, gathered %.1f, perm %.1f, leaf map %.1f)",
        T->seconds, T->cpu_seconds, T->threads, texels, T->num_nodes, T->leaf_texels, T->buried,
        T->sealed, (unsigned long long)T->num_links, (unsigned long long)T->rays,
        transfer_bytes(T) / mib, g->TG.bytes / mib, g->TG.mem[TRG_MEM_NODES] / mib,
        g->TG.mem[TRG_MEM_LINKS] / mib, g->TG.mem[TRG_MEM_GATHERED] / mib,
        g->TG.mem[TRG_MEM_PERM] / mib, g->TG.mem[TRG_MEM_LEAF] / mib);
    int np = g->prof_n < AG_PROF_MAX ? g->prof_n : AG_PROF_MAX;
    for (int i = 0; i < AG_PROF_STEPS && np && n > 0 && (size_t)n < sizeof out->info; i++)
        n += snprintf(
            out->info + n, sizeof out->info - (size_t)n, "%s%s %.2f / %.2f",
            i ? ", " : "; relight steps (median ms wall / process CPU, profile): ", prof_names[i],
            st_median_f(g->prof[0][i], np), st_median_f(g->prof[1][i], np));
    return true;
}

// ---- uniforms for the regular pass ------------------------------------------

#define G(self) ((agi *)(self))
static void u_ind(void *s, st_shader *sh, GLint l, const st_frame *f) {
    st_shader_texture(sh, "ag_indirect_tex", GL_TEXTURE_2D, G(s)->tex[T_INDIRECT]);
}
static void u_comb(void *s, st_shader *sh, GLint l, const st_frame *f) {
    st_shader_texture(sh, "ag_combined_tex", GL_TEXTURE_2D, G(s)->tex[T_COMBINED]);
}
static void u_tri(void *s, st_shader *sh, GLint l, const st_frame *f) {
    st_shader_texture(sh, "ag_tri_tex", GL_TEXTURE_BUFFER, G(s)->tri_tex);
}
static void u_base(void *s, st_shader *sh, GLint l, const st_frame *f) {
    st_shader_texture(sh, "ag_base_tex", GL_TEXTURE_BUFFER, G(s)->base_tex);
}
static void u_lookup(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, G(s)->lookup);
}
static void u_display(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, ip(G(s), P_DISPLAY));
}

static const st_uniform uniforms_table[] = {
    {"ag_indirect_tex", u_ind}, {"ag_combined_tex", u_comb}, {"ag_tri_tex", u_tri},
    {"ag_base_tex", u_base},    {"ag_lookup", u_lookup},     {"ag_display", u_display},
};

static int uniforms(void *self, const st_uniform **out) {
    *out = uniforms_table;
    return (int)(sizeof uniforms_table / sizeof uniforms_table[0]);
}

ST_PLUGIN(.name = "atlas_gi",
          .description =
              "texture-atlas global illumination (Merz 2010): G-buffer atlas, precomputed "
              "transfer (default) or the thesis' Hammersley gather, visibility, more bounces, "
              "textured back onto the scene",
          ST_PARAMS(params), .requires = "shadow_map?", .provides = "atlas_gi",
          .regular_include = "atlas_gi/regular.glsl", .create = create, .destroy = destroy,
          .num_passes = num_passes, .pass_info = pass_info, .uniforms = uniforms, .needed = needed,
          .on_pass = on_pass, .param_changed = param_changed, .reload = reload,
          .progress = progress,
          .light_types = ST_LIGHT_BITS_ALL /* direct light through common/lighting.glsl */)
