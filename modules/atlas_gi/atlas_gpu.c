// atlas_gi: the atlas on the GPU (its textures, framebuffers, the G-buffer's
// points and model type, the regular pass' triangle table), the scene's
// triangles (visibility) and the resolve that both modes end with.
#include "agi.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// The atlas' textures, owned by the world (declared in alloc_textures).
static const char *const tex_name[T_COUNT] = {
    "atlas_gi.position", "atlas_gi.normal",   "atlas_gi.albedo",  "atlas_gi.direct",
    "atlas_gi.area",     "atlas_gi.bounce0",  "atlas_gi.bounce1", "atlas_gi.accum",
    "atlas_gi.indirect", "atlas_gi.combined", "atlas_gi.stats",   "atlas_gi.near"};
static const GLenum tex_format[T_COUNT] = {GL_RGBA32F, GL_RGBA32F, GL_RGBA16F, GL_RGBA32F,
                                           GL_R32F,    GL_RGBA32F, GL_RGBA32F, GL_RGBA32F,
                                           GL_RGBA32F, GL_RGBA32F, GL_RGBA32F, GL_R8};
// Its buffers: the world's (st_world_buffer, _texture; 0, 3 to 6), the model
// type's (1, 2) and the BVH's (7, 8), tracked by the world for --stats.
const char *const agi_buffer_names[] = {
    "atlas_gi.points",        "atlas_gi.vertices",      "atlas_gi.indices",
    "atlas_gi.triangles",     "atlas_gi.triangles_tex", "atlas_gi.mesh_base",
    "atlas_gi.mesh_base_tex", "atlas_gi.bvh_nodes",     "atlas_gi.bvh_triangles"};
enum { NUM_BUFFERS = 9 };

void agi_release_atlas_gpu(agi *g) {
    for (int i = 0; i < T_COUNT; i++) // fresh textures for the next atlas, as before
        st_world_declare_target(g->w, tex_name[i], NULL, &(st_err){0});
    memset(g->tex, 0, sizeof g->tex);
    for (size_t i = 0; i < NUM_BUFFERS; i++) // deletes the world's own
        st_world_untrack(g->w, agi_buffer_names[i]);
    GLuint fbos[5] = {g->fbo_gb, g->fbo_l0, g->fbo_gather[0], g->fbo_gather[1], g->fbo_resolve};
    glDeleteFramebuffers(5, fbos);
    g->fbo_gb = g->fbo_l0 = g->fbo_gather[0] = g->fbo_gather[1] = g->fbo_resolve = 0;
    g->l0_partial = false;
    if (g->pts_vao) glDeleteVertexArrays(1, &g->pts_vao);
    g->pts_vao = 0;
    st_bvh_gpu_free(&g->B_gpu);
    if (g->type.vao) st_model_type_destroy(&g->type);
    free(g->models);
    free(g->gmeshes);
    g->models = NULL;
    g->gmeshes = NULL;
    g->num_models = 0;
    st_bvh_free(&g->B);
    g->have_bvh = false;
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

// The atlas on the CPU (atlas.h), and the scene's extent for the visibility
// rays' offset.
static bool atlas_cpu(agi *g, st_err *err) {
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
    return true;
}

// The G-buffer pass draws the split meshes as a model type of their own.
static bool build_model_type(agi *g, st_err *err) {
    const atlas *A = &g->A;
    g->num_models = A->num_meshes;
    g->gmeshes = calloc(A->num_meshes ? (size_t)A->num_meshes : 1, sizeof *g->gmeshes);
    g->models = calloc(A->num_meshes ? (size_t)A->num_meshes : 1, sizeof *g->models);
    if (!g->gmeshes || !g->models) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int i = 0; i < A->num_meshes; i++)
        g->gmeshes[i] = A->meshes[i].mesh;
    return st_model_type_build(&g->type, "atlas_gi", g->gmeshes, A->num_meshes, NULL, g->models,
                               err);
}

// The resolve's mask: the texels where it can write anything but 0 (a
// texel with area, or a gutter texel next to one); the rest of the atlas,
// often most of it, is discarded there (whole blocks skip the shader).
static bool upload_near(agi *g, st_err *err) {
    int W = g->W, H = g->H;
    uint8_t *m = calloc((size_t)W * H, 1);
    if (!m) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            if (!(g->A.area[(size_t)y * W + x] > 0)) continue;
            for (int v = y > 0 ? y - 1 : 0; v <= y + 1 && v < H; v++)
                for (int u = x > 0 ? x - 1 : 0; u <= x + 1 && u < W; u++)
                    m[(size_t)v * W + u] = 255;
        }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1); // rows of W bytes (atlas_size may be odd)
    glTextureSubImage2D(g->tex[T_NEAR], 0, 0, 0, W, H, GL_RED, GL_UNSIGNED_BYTE, m);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    free(m);
    return true;
}

// The atlas' textures (declared with the world) and framebuffers.
static bool alloc_textures(agi *g, st_err *err) {
    int W = g->W, H = g->H;
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
    glTextureSubImage2D(g->tex[T_AREA], 0, 0, 0, W, H, GL_RED, GL_FLOAT, g->A.area);
    if (!upload_near(g, err)) return false;
    // The resolve never writes where T_NEAR is 0: zero there once.
    const float zero[4] = {0, 0, 0, 0};
    for (int i = T_INDIRECT; i <= T_STATS; i++)
        glClearTexImage(g->tex[i], 0, GL_RGBA, GL_FLOAT, zero);
    g->fbo_gb = make_fbo(&g->tex[T_POS], 4);
    g->fbo_l0 = make_fbo(&g->tex[T_L0], 1);
    g->fbo_gather[0] = make_fbo((GLuint[]){g->tex[T_BOUNCE0], g->tex[T_ACCUM]}, 2);
    g->fbo_gather[1] = make_fbo((GLuint[]){g->tex[T_BOUNCE1], g->tex[T_ACCUM]}, 2);
    g->fbo_resolve = make_fbo(&g->tex[T_INDIRECT], 3);
    return true;
}

// Conservative coverage: points for texels the rasterizer misses.
static bool upload_points(agi *g, st_err *err) {
    const atlas *A = &g->A;
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
    GLuint vbo = st_world_buffer(g->w, agi_buffer_names[0],
                                 (A->num_points ? A->num_points : 1) * 14 * sizeof(float), pv, err);
    free(pv);
    if (!vbo) return false;
    glCreateVertexArrays(1, &g->pts_vao);
    glVertexArrayVertexBuffer(g->pts_vao, 0, vbo, 0, 14 * sizeof(float));
    const int comps[5] = {2, 3, 3, 3, 3}, offs[5] = {0, 2, 5, 8, 11};
    for (GLuint a = 0; a < 5; a++) {
        glEnableVertexArrayAttrib(g->pts_vao, a);
        glVertexArrayAttribFormat(g->pts_vao, a, comps[a], GL_FLOAT, GL_FALSE,
                                  (GLuint)(offs[a] * sizeof(float)));
        glVertexArrayAttribBinding(g->pts_vao, a, 0);
    }
    return true;
}

// The regular pass' triangle table and per-mesh bases, as buffer textures.
static bool upload_lookup(agi *g, st_err *err) {
    const st_scene *sc = st_world_scene(g->w);
    const atlas *A = &g->A;
    GLint max_tbo = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_tbo);
    if ((uint64_t)A->num_tris * 3 > (uint64_t)max_tbo)
        return st_fail(err, ST_ERR_RUNTIME,
                       "%u triangles exceed the GPU's texture buffer limit (%d texels)",
                       A->num_tris, max_tbo);
    GLuint tri =
        st_world_buffer(g->w, agi_buffer_names[3],
                        (A->num_tris ? A->num_tris : 1) * 12 * sizeof(float), A->lookup, err);
    if (!tri || !st_world_buffer_texture(g->w, agi_buffer_names[4], tri, GL_RGBA32F, err))
        return false;
    int nm = sc->num_meshes ? sc->num_meshes : 1;
    int32_t *base = malloc((size_t)nm * 2 * sizeof *base);
    if (!base) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int i = 0; i < 2 * nm; i++)
        base[i] = sc->num_meshes ? A->mesh_base[i] : -1;
    GLuint bb =
        st_world_buffer(g->w, agi_buffer_names[5], (size_t)nm * 2 * sizeof *base, base, err);
    free(base);
    return bb && st_world_buffer_texture(g->w, agi_buffer_names[6], bb, GL_RG32I, err);
}

bool agi_build_atlas(agi *g, st_err *err) {
    agi_release_atlas_gpu(g);
    if (!atlas_cpu(g, err) || !build_model_type(g, err) || !alloc_textures(g, err) ||
        !upload_points(g, err) || !upload_lookup(g, err))
        return false;
    if (!st_world_track(g->w, agi_buffer_names[1], GL_BUFFER, g->type.vbo.id, err) ||
        !st_world_track(g->w, agi_buffer_names[2], GL_BUFFER, g->type.ibo.id, err))
        return false;
    g->atlas_dirty = false;
    g->gb_dirty = true;
    return st_gl_check("atlas_gi atlas", err);
}

float *agi_scene_triangles(const agi *g, uint32_t *count, st_err *err) {
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

// ---- the resolve -----------------------------------------------------------------

bool agi_resolve(agi *g, st_err *err) {
    st_shader *sh = st_world_program(g->w, g->p, PR_RESOLVE, err);
    if (!sh) return false;
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_resolve);
    glViewport(0, 0, g->W, g->H);
    st_shader_use(sh);
    st_shader_texture(sh, "ag_pos", GL_TEXTURE_2D, g->tex[T_POS]);
    st_shader_texture(sh, "ag_l0", GL_TEXTURE_2D, g->tex[T_L0]);
    st_shader_texture(sh, "ag_accum", GL_TEXTURE_2D, g->tex[T_ACCUM]);
    st_shader_texture(sh, "ag_near", GL_TEXTURE_2D, g->tex[T_NEAR]);
    st_shader_set_float(sh, "ag_frames", (float)g->frames);
    st_draw_fullscreen();
    return true;
}
