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
#include "atlas.h"
#include "bvh.h"
#include "transfer.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

typedef struct agi {
    st_world *w;
    const double *p;
    atlas A;
    double extent;
    bvh B;
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
    GLuint nodes_ssbo, tris_ssbo;
    st_shader *sh_gb, *sh_gbp, *sh_gather, *sh_gather_vis, *sh_resolve;
    // Precomputed transfer (mode=transfer), built on first use per atlas.
    transfer T;
    bool have_transfer;
    GLuint tr_buf[6]; // nodes, flux, gathered, link offsets, links, texel slots
    GLuint leaf_tex;
    st_shader *sh_tr_reduce, *sh_tr_gather, *sh_tr_push;
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
    glDeleteBuffers(6, g->tr_buf);
    memset(g->tr_buf, 0, sizeof g->tr_buf);
    if (g->leaf_tex) glDeleteTextures(1, &g->leaf_tex);
    g->leaf_tex = 0;
    transfer_free(&g->T);
    g->have_transfer = false;
}

static void release_atlas_gpu(agi *g) {
    glDeleteTextures(T_COUNT, g->tex);
    memset(g->tex, 0, sizeof g->tex);
    GLuint fbos[4] = {g->fbo_gb, g->fbo_gather[0], g->fbo_gather[1], g->fbo_resolve};
    glDeleteFramebuffers(4, fbos);
    g->fbo_gb = g->fbo_gather[0] = g->fbo_gather[1] = g->fbo_resolve = 0;
    if (g->pts_vao) glDeleteVertexArrays(1, &g->pts_vao);
    GLuint bufs[5] = {g->pts_vbo, g->tri_buf, g->base_buf, g->nodes_ssbo, g->tris_ssbo};
    glDeleteBuffers(5, bufs);
    GLuint texs[2] = {g->tri_tex, g->base_tex};
    glDeleteTextures(2, texs);
    g->pts_vao = g->pts_vbo = g->tri_buf = g->base_buf = g->nodes_ssbo = g->tris_ssbo = g->tri_tex =
        g->base_tex = 0;
    if (g->type.vao) st_model_type_destroy(&g->type);
    free(g->models);
    free(g->gmeshes);
    g->models = NULL;
    g->gmeshes = NULL;
    g->num_models = 0;
    bvh_free(&g->B);
    g->have_bvh = false;
    release_transfer(g);
    atlas_free(&g->A);
}

static GLuint make_tex(int w, int h, GLenum fmt, int levels, bool linear) {
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, levels, fmt, w, h);
    GLint min = levels > 1 ? GL_NEAREST_MIPMAP_NEAREST : linear ? GL_LINEAR : GL_NEAREST;
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, min);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, linear ? GL_LINEAR : GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
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
    g->tex[T_POS] = make_tex(W, H, GL_RGBA32F, 1, false);
    g->tex[T_NORMAL] = make_tex(W, H, GL_RGBA32F, 1, false);
    g->tex[T_ALBEDO] = make_tex(W, H, GL_RGBA16F, 1, false);
    g->tex[T_L0] = make_tex(W, H, GL_RGBA32F, 1, false);
    g->tex[T_AREA] = make_tex(W, H, GL_R32F, 1, false);
    g->tex[T_BOUNCE0] = make_tex(W, H, GL_RGBA32F, 1, false);
    g->tex[T_BOUNCE1] = make_tex(W, H, GL_RGBA32F, 1, false);
    g->tex[T_ACCUM] = make_tex(W, H, GL_RGBA32F, 1, false);
    g->tex[T_INDIRECT] = make_tex(W, H, GL_RGBA32F, 1, true);
    g->tex[T_COMBINED] = make_tex(W, H, GL_RGBA32F, 1, true);
    g->tex[T_STATS] = make_tex(W, H, GL_RGBA32F, g->stats_top + 1, false);
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
    bool ok = bvh_build(&g->B, c, n, err);
    free(c);
    if (!ok) return false;
    glCreateBuffers(1, &g->nodes_ssbo);
    glNamedBufferStorage(g->nodes_ssbo, (GLsizeiptr)(g->B.num_nodes * 8 * sizeof(float)),
                         g->B.nodes, 0);
    glCreateBuffers(1, &g->tris_ssbo);
    glNamedBufferStorage(g->tris_ssbo, (GLsizeiptr)((n ? n : 1) * 12 * sizeof(float)), g->B.tris,
                         0);
    g->have_bvh = true;
    return st_gl_check("atlas_gi bvh", err);
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
    const transfer *T = &g->T;
    size_t nn = T->num_nodes ? (size_t)T->num_nodes : 1;
    float *nodes = calloc(nn * 12, sizeof *nodes);
    uint32_t *links = malloc((T->num_links ? T->num_links : 1) * 2 * sizeof *links);
    if (!nodes || !links) {
        free(nodes);
        free(links);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for the transfer's GPU copy");
    }
    for (int i = 0; i < T->num_nodes; i++) {
        const tr_node *n = &T->nodes[i];
        float *o8 = nodes + 12 * (size_t)i;
        memcpy(o8, n->c, 3 * sizeof(float));
        o8[3] = n->area;
        memcpy(o8 + 4, n->n, 3 * sizeof(float));
        o8[7] = cosf(n->cone);
        int32_t info[4] = {n->child, (int32_t)n->begin, (int32_t)n->end, n->parent};
        memcpy(o8 + 8, info, sizeof info);
    }
    for (uint64_t k = 0; k < T->num_links; k++) {
        links[2 * k] = T->link_node[k];
        memcpy(&links[2 * k + 1], &T->link_w[k], 4);
    }
    uint32_t zero_off[2] = {0, 0};
    glCreateBuffers(6, g->tr_buf);
    glNamedBufferStorage(g->tr_buf[0], (GLsizeiptr)(nn * 12 * sizeof(float)), nodes, 0);
    glNamedBufferStorage(g->tr_buf[1], (GLsizeiptr)(nn * 4 * sizeof(float)), NULL, 0);
    glNamedBufferStorage(g->tr_buf[2], (GLsizeiptr)(nn * 16 * sizeof(float)), NULL, 0);
    glNamedBufferStorage(g->tr_buf[3], (GLsizeiptr)((nn + 1) * sizeof(uint32_t)),
                         T->link_off ? T->link_off : zero_off, 0);
    glNamedBufferStorage(g->tr_buf[4],
                         (GLsizeiptr)((T->num_links ? T->num_links : 1) * 2 * sizeof(uint32_t)),
                         links, 0);
    uint32_t nperm = T->num_nodes ? T->nodes[0].end : 0;
    glNamedBufferStorage(g->tr_buf[5], (GLsizeiptr)((nperm ? nperm : 1) * sizeof(uint32_t)),
                         nperm ? T->perm : zero_off, 0);
    free(nodes);
    free(links);
    glCreateTextures(GL_TEXTURE_2D, 1, &g->leaf_tex);
    glTextureStorage2D(g->leaf_tex, 1, GL_R32I, g->W, g->H);
    glTextureParameteri(g->leaf_tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(g->leaf_tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureSubImage2D(g->leaf_tex, 0, 0, 0, g->W, g->H, GL_RED_INTEGER, GL_INT, T->texel_leaf);
    g->have_transfer = true;
    return st_gl_check("atlas_gi transfer upload", err);
}

// The sample texture (thesis 4.5): X_i = (i/N, radical inverse base 2 of i).
static void ensure_hammersley(agi *g) {
    int n = ip(g, P_SAMPLES);
    if (g->ham_n == n && g->ham_tex) return;
    float *v = realloc(g->ham, (size_t)n * 2 * sizeof *v);
    if (!v) return;
    g->ham = v;
    if (g->ham_tex) glDeleteTextures(1, &g->ham_tex);
    g->ham_tex = st_hammersley_texture(n, v);
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
        if (g->pick_tex) glDeleteTextures(1, &g->pick_tex);
        glCreateTextures(GL_TEXTURE_1D, 1, &g->pick_tex);
        glTextureStorage1D(g->pick_tex, 1, GL_RGBA32F, n);
        glTextureParameteri(g->pick_tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(g->pick_tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
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
    snprintf(defs, sizeof defs, "ST_MAX_LIGHTS %d\n%s", ST_MAX_LIGHTS,
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
    release_atlas_gpu(g);
    if (g->ham_tex) glDeleteTextures(1, &g->ham_tex);
    if (g->pick_tex) glDeleteTextures(1, &g->pick_tex);
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
    st_shader_destroy(g->sh_tr_reduce);
    st_shader_destroy(g->sh_tr_gather);
    st_shader_destroy(g->sh_tr_push);
    free(g);
}

static void *create(st_world *w, const double *p, st_err *err) {
    agi *g = calloc(1, sizeof *g);
    if (!g) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    g->w = w;
    g->p = p;
    g->rel_err = INFINITY;
    bool ok =
        compile_gbuffer(g, st_world_has_module(w, "shadow_map"), err) &&
        (g->sh_gather =
             st_shader_load("common/fullscreen.vert", "atlas_gi/gather.frag", NULL, err)) &&
        (g->sh_gather_vis = st_shader_load("common/fullscreen.vert", "atlas_gi/gather.frag",
                                           "AG_VISIBILITY 1\n", err)) &&
        (g->sh_resolve =
             st_shader_load("common/fullscreen.vert", "atlas_gi/resolve.frag", NULL, err)) &&
        (g->sh_tr_reduce = st_shader_load_compute("atlas_gi/transfer_reduce.comp", NULL, err)) &&
        (g->sh_tr_gather = st_shader_load_compute("atlas_gi/transfer_gather.comp", NULL, err)) &&
        (g->sh_tr_push =
             st_shader_load("common/fullscreen.vert", "atlas_gi/transfer_push.frag", NULL, err)) &&
        build_atlas(g, err);
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

static bool gbuffer_pass(agi *g, const st_frame *f, st_err *err) {
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

// mode=transfer: every bounce is a reduction up the cluster tree, one pass
// over the links and a push down to the texels. Deterministic: one frame.
static bool transfer_pass(agi *g, const st_frame *f, st_err *err) {
    if (!ensure_transfer(g, err)) return false;
    const transfer *T = &g->T;
    for (int i = 0; i < 6; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, g->tr_buf[i]);
    const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(g->tex[T_ACCUM], 0, GL_RGBA, GL_FLOAT, zero);
    glViewport(0, 0, g->W, g->H);
    glDisable(GL_DEPTH_TEST);
    int bounces = ip(g, P_BOUNCES);
    for (int b = 0; b < bounces && T->num_nodes; b++) {
        bool last = b == bounces - 1;
        GLuint prev = g->tex[b & 1 ? T_BOUNCE0 : T_BOUNCE1];
        st_shader *r = g->sh_tr_reduce;
        st_shader_use(r);
        st_shader_texture(r, "ag_l0", GL_TEXTURE_2D, g->tex[T_L0]);
        st_shader_texture(r, "ag_prev", GL_TEXTURE_2D, prev);
        st_shader_set_int(r, "ag_use_prev", b > 0);
        st_shader_texture(r, "ag_area", GL_TEXTURE_2D, g->tex[T_AREA]);
        for (int l = T->num_levels - 1; l >= 0; l--) {
            int lb = T->level_begin[l], le = T->level_begin[l + 1];
            st_shader_set_int(r, "ag_begin", lb);
            st_shader_set_int(r, "ag_end", le);
            glDispatchCompute((GLuint)((le - lb + 63) / 64), 1, 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
        st_shader_use(g->sh_tr_gather);
        st_shader_set_int(g->sh_tr_gather, "ag_num_nodes", T->num_nodes);
        st_world_apply_uniforms(g->w, g->sh_tr_gather, f); // the medium
        glDispatchCompute((GLuint)((T->num_nodes + 63) / 64), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        GLuint fbo = g->fbo_gather[b & 1];
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, last ? GL_COLOR_ATTACHMENT1 : GL_NONE};
        glNamedFramebufferDrawBuffers(fbo, 2, bufs);
        glDisablei(GL_BLEND, 0);
        glDisablei(GL_BLEND, 1);
        st_shader *p = g->sh_tr_push;
        st_shader_use(p);
        st_shader_texture(p, "ag_leaf", GL_TEXTURE_2D, g->leaf_tex);
        st_shader_texture(p, "ag_albedo", GL_TEXTURE_2D, g->tex[T_ALBEDO]);
        st_shader_texture(p, "ag_pos", GL_TEXTURE_2D, g->tex[T_POS]);
        st_draw_fullscreen();
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    }
    for (int i = 0; i < 6; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, 0);
    g->frames = 1;
    g->restart = false;
    resolve(g);
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
    if (vis) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, g->nodes_ssbo);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, g->tris_ssbo);
    }
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
    st_shader *all[8] = {g->sh_gb,      g->sh_gbp,       g->sh_gather,    g->sh_gather_vis,
                         g->sh_resolve, g->sh_tr_reduce, g->sh_tr_gather, g->sh_tr_push};
    for (int i = 0; i < 8; i++)
        if (!st_shader_reload(all[i], err)) return false;
    g->gb_dirty = true;
    return true;
}

static bool progress(void *self, st_progress *out) {
    agi *g = self;
    out->converged = g->converged;
    out->frames = (uint32_t)g->frames;
    out->error = g->rel_err;
    if (g->have_transfer) {
        const transfer *T = &g->T;
        uint32_t texels = T->num_nodes ? T->nodes[0].end : 0;
        snprintf(out->info, sizeof out->info,
                 "transfer precompute %.2f s (CPU %.2f s) on %d threads, %u texels, %d nodes (<= "
                 "%d texels per "
                 "leaf, %u buried), %llu links, "
                 "%llu rays, %.1f MiB",
                 T->seconds, T->cpu_seconds, T->threads, texels, T->num_nodes, T->leaf_texels,
                 T->buried, (unsigned long long)T->num_links, (unsigned long long)T->rays,
                 transfer_bytes(T) / 1048576.0);
    }
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
