// atlas_gi: atlas generation and exact texel coverage (see atlas.h):
// atlas_build's steps in order, the split meshes and the triangle tables.
// The steps live in atlas_charts.c (charts and packing) and
// atlas_coverage.c (exact coverage); atlas_builder.h is their shared state.
#include "atlas_builder.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool atlas_meshes_have_uv1(const st_mesh *meshes, int n) {
    int with_tris = 0;
    for (int i = 0; i < n; i++) {
        if (!meshes[i].num_triangles) continue;
        with_tris++;
        if (!meshes[i].uv1) return false;
    }
    return with_tris > 0;
}

// ---- split meshes -------------------------------------------------------

typedef struct corner_rec {
    uint32_t v;
    int32_t chart;
    uint32_t corner;
} corner_rec;

static int cmp_corner(const void *a, const void *b) {
    const corner_rec *x = a, *y = b;
    if (x->v != y->v) return x->v < y->v ? -1 : 1;
    if (x->chart != y->chart) return x->chart < y->chart ? -1 : 1;
    return (x->corner > y->corner) - (x->corner < y->corner);
}

// Copies one side of a scene mesh with a vertex per (vertex, chart) and its
// atlas uv; the back side flips normals and winding.
static bool build_side_mesh(const builder *B, const atlas *A, int si, atlas_mesh *am) {
    const side *sd = &B->sides[si];
    const st_mesh *src = &B->meshes[sd->mesh];
    st_mesh *m = &am->mesh;
    memset(m, 0, sizeof *m);
    snprintf(m->name, sizeof m->name, "%.56s%s", src->name, sd->back ? ".back" : "");
    memcpy(m->model, src->model, sizeof m->model);
    memcpy(m->albedo, src->albedo, sizeof m->albedo);
    memcpy(m->emission, src->emission, sizeof m->emission);
    m->double_sided = false;
    size_t nc = (size_t)sd->count * 3;
    corner_rec *cr = malloc(nc * sizeof *cr);
    m->indices = malloc(nc * sizeof *m->indices);
    m->positions = malloc(nc * 3 * sizeof(float));
    m->normals = malloc(nc * 3 * sizeof(float));
    m->uv1 = malloc(nc * 2 * sizeof(float));
    if (!cr || !m->indices || !m->positions || !m->normals || !m->uv1) {
        free(cr);
        st_mesh_free(m);
        return false;
    }
    for (size_t c = 0; c < nc; c++) {
        uint32_t k = (uint32_t)(c / 3), cc = (uint32_t)(c % 3);
        uint32_t srcc = sd->back && cc ? 3 - cc : cc;
        cr[c] = (corner_rec){src->indices[3 * k + srcc],
                             B->o->use_uv1 ? 0 : B->tri_chart[sd->first + k], (uint32_t)c};
    }
    qsort(cr, nc, sizeof *cr, cmp_corner);
    uint32_t nv = 0;
    for (size_t i = 0; i < nc; i++) {
        if (!i || cr[i].v != cr[i - 1].v || cr[i].chart != cr[i - 1].chart) {
            const float *p = src->positions + 3 * cr[i].v, *n = src->normals + 3 * cr[i].v;
            uint32_t k = cr[i].corner / 3, cc = cr[i].corner % 3;
            for (int r = 0; r < 3; r++)
                m->positions[3 * nv + r] = p[r], m->normals[3 * nv + r] = sd->back ? -n[r] : n[r];
            m->uv1[2 * nv] = (float)(B->uv[sd->first + k][cc][0] / A->width);
            m->uv1[2 * nv + 1] = (float)(B->uv[sd->first + k][cc][1] / A->height);
            nv++;
        }
        m->indices[cr[i].corner] = nv - 1;
    }
    free(cr);
    m->num_vertices = nv;
    m->num_triangles = sd->count;
    am->scene_mesh = sd->mesh;
    am->back = sd->back;
    am->first_tri = sd->first;
    return true;
}

// ---- triangle tables --------------------------------------------------------

// Triangle k for the G-buffer's lookups: world v0, e1, e2 and the atlas uvs.
static void write_tri(const builder *B, atlas *A, uint32_t k) {
    const wtri *w = &B->tris[k];
    float *t = A->tris + 16 * (size_t)k;
    for (int r = 0; r < 3; r++) {
        t[r] = (float)w->p[0][r];
        t[4 + r] = (float)(w->p[1][r] - w->p[0][r]);
        t[8 + r] = (float)(w->p[2][r] - w->p[0][r]);
    }
    t[3] = (float)(B->uv[k][0][0] / A->width);
    t[7] = (float)(B->uv[k][0][1] / A->height);
    t[11] = (float)(B->uv[k][1][0] / A->width);
    t[12] = (float)(B->uv[k][1][1] / A->height);
    t[13] = (float)(B->uv[k][2][0] / A->width);
    t[14] = (float)(B->uv[k][2][1] / A->height);
    t[15] = 0;
}

// Triangle k as the regular pass reads it: v0, uv0 and the gradients of u
// and v in the triangle's plane: g = a e1 + b e2 with g . e1 = du1, g . e2 = du2.
static void write_lookup(const builder *B, atlas *A, uint32_t k) {
    const wtri *w = &B->tris[k];
    double e1[3], e2[3];
    for (int r = 0; r < 3; r++)
        e1[r] = w->p[1][r] - w->p[0][r], e2[r] = w->p[2][r] - w->p[0][r];
    double a11 = dot3(e1, e1), a12 = dot3(e1, e2), a22 = dot3(e2, e2), det = a11 * a22 - a12 * a12;
    float *L = A->lookup + 12 * (size_t)k;
    for (int c = 0; c < 2; c++) {
        double scale = c ? A->height : A->width;
        double d1 = (B->uv[k][1][c] - B->uv[k][0][c]) / scale,
               d2 = (B->uv[k][2][c] - B->uv[k][0][c]) / scale;
        double ca = 0, cb = 0;
        if (det > 1e-30 * a11 * a22)
            ca = (a22 * d1 - a12 * d2) / det, cb = (a11 * d2 - a12 * d1) / det;
        for (int r = 0; r < 3; r++)
            L[4 * (c + 1) + r] = (float)(ca * e1[r] + cb * e2[r]);
    }
    for (int r = 0; r < 3; r++)
        L[r] = (float)w->p[0][r];
    L[3] = (float)(B->uv[k][0][0] / A->width);
    L[7] = (float)(B->uv[k][0][1] / A->height);
    L[11] = 0;
}

// Split meshes, the triangle table and per-mesh bases.
static bool build_meshes(const builder *B, atlas *A, int num_meshes, st_err *err) {
    size_t nt = B->num_tris ? B->num_tris : 1;
    A->num_charts = B->num_charts;
    A->meshes = calloc(B->num_sides ? (size_t)B->num_sides : 1, sizeof *A->meshes);
    A->tris = malloc(nt * 16 * sizeof *A->tris);
    A->lookup = malloc(nt * 12 * sizeof *A->lookup);
    A->mesh_base = malloc((num_meshes ? (size_t)num_meshes : 1) * 2 * sizeof *A->mesh_base);
    if (!A->meshes || !A->tris || !A->lookup || !A->mesh_base)
        return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    for (int m = 0; m < 2 * num_meshes; m++)
        A->mesh_base[m] = -1;
    for (int si = 0; si < B->num_sides; si++) {
        if (!build_side_mesh(B, A, si, &A->meshes[si]))
            return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
        A->num_meshes++;
        A->mesh_base[2 * B->sides[si].mesh + B->sides[si].back] = (int32_t)B->sides[si].first;
    }
    A->num_tris = B->num_tris;
    for (uint32_t k = 0; k < B->num_tris; k++) {
        write_tri(B, A, k);
        write_lookup(B, A, k);
    }
    return true;
}

// keep_chart_map: the per-texel chart ids and each chart's scene mesh.
static bool keep_chart_map(const builder *B, atlas *A, cover_ctx *C, st_err *err) {
    A->chart = C->chart;
    C->chart = NULL;
    A->chart_mesh = malloc((B->num_charts ? (size_t)B->num_charts : 1) * sizeof *A->chart_mesh);
    if (!A->chart_mesh) return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    for (int i = 0; i < B->num_charts; i++)
        A->chart_mesh[i] = B->sides[B->o->use_uv1 ? i : B->charts[i].side].mesh;
    return true;
}

// ---- build ------------------------------------------------------------------

void atlas_free(atlas *a) {
    for (int i = 0; i < a->num_meshes; i++)
        st_mesh_free(&a->meshes[i].mesh);
    free(a->meshes);
    free(a->area);
    free(a->chart);
    free(a->chart_mesh);
    free(a->tris);
    free(a->lookup);
    free(a->mesh_base);
    free(a->points);
    memset(a, 0, sizeof *a);
}

static void builder_free(builder *B) {
    free(B->sides);
    free(B->tris);
    free(B->tri_chart);
    free(B->c2);
    free(B->uv);
    free(B->charts);
    free(B->single);
}

static bool check_opts(const st_mesh *meshes, int num_meshes, const atlas_opts *o, st_err *err) {
    if (o->gutter < 1 || o->size < 1 || o->max_size < 1)
        return st_fail(err, ST_ERR_INPUT, "atlas: bad options");
    if (o->use_uv1 && !atlas_meshes_have_uv1(meshes, num_meshes))
        return st_fail(err, ST_ERR_INPUT, "atlas: not every mesh has TEXCOORD_1");
    return true;
}

// The per-triangle arrays of the builder and the coverage.
static bool alloc_per_triangle(builder *B, cover_ctx *C, st_err *err) {
    size_t nt = B->num_tris ? B->num_tris : 1;
    B->tri_chart = malloc(nt * sizeof *B->tri_chart);
    B->c2 = malloc(nt * sizeof *B->c2);
    B->uv = malloc(nt * sizeof *B->uv);
    B->single = calloc(nt, sizeof *B->single);
    C->tri_hit = calloc(nt, sizeof *C->tri_hit);
    C->amesh_of_tri = malloc(nt * sizeof *C->amesh_of_tri);
    if (!B->tri_chart || !B->c2 || !B->uv || !B->single || !C->tri_hit || !C->amesh_of_tri)
        return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    for (int si = 0; si < B->num_sides; si++)
        for (uint32_t k = 0; k < B->sides[si].count; k++)
            C->amesh_of_tri[B->sides[si].first + k] = si;
    C->B = B;
    C->A = NULL;
    return true;
}

// Layout and coverage: a chart that folds over itself in the plane
// (coverage > 1 somewhere) is split into single triangles and the layout
// redone.
static bool layout_and_cover(builder *B, atlas *A, cover_ctx *C, st_err *err) {
    C->A = A;
    for (int attempt = 0; attempt < 3; attempt++) {
        bool folded = false;
        if (!ab_make_layout(B, A, err) || !ab_cover(B, A, C, &folded, err)) return false;
        if (!folded) break;
    }
    return true;
}

bool atlas_build(atlas *A, const st_mesh *meshes, int num_meshes, const atlas_opts *o,
                 st_err *err) {
    memset(A, 0, sizeof *A);
    builder B = {.meshes = meshes, .num_meshes = num_meshes, .o = o};
    cover_ctx C = {0};
    bool ok = check_opts(meshes, num_meshes, o, err) && ab_gather_triangles(&B, err) &&
              alloc_per_triangle(&B, &C, err) && layout_and_cover(&B, A, &C, err);
    if (ok) ab_invariants(&B, A, &C);
    ok = ok && ab_points(&B, A, &C, err) && build_meshes(&B, A, num_meshes, err) &&
         (!o->keep_chart_map || keep_chart_map(&B, A, &C, err));
    ab_cover_free(&C);
    builder_free(&B);
    if (!ok) atlas_free(A);
    return ok;
}
