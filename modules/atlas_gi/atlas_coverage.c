// atlas_gi: exact texel coverage (see atlas.h and atlas_builder.h). Every
// triangle is clipped against each texel square it touches: the pieces' areas
// give each texel's world area and find overlaps and folded charts; texels
// whose centre no triangle covers become points with the area-weighted
// position and normal of their covered part.
#include "atlas_builder.h"
#include <stdlib.h>
#include <string.h>

typedef struct {
    double x, y;
} v2;

// Keeps the part of polygon `in` with coordinate `axis` >= v (keep_ge) or <= v.
static int clip_half(const v2 *in, int n, int axis, double v, bool keep_ge, v2 *out) {
    int m = 0;
    for (int i = 0; i < n; i++) {
        v2 a = in[i], b = in[(i + 1) % n];
        double da = (axis ? a.y : a.x) - v, db = (axis ? b.y : b.x) - v;
        if (!keep_ge) da = -da, db = -db;
        if (da >= 0) out[m++] = a;
        if ((da >= 0) != (db >= 0)) {
            double t = da / (da - db);
            out[m++] = (v2){a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
        }
    }
    return m;
}

static double poly_area(const v2 *p, int n, v2 *centroid) {
    double a = 0, cx = 0, cy = 0;
    for (int i = 0; i < n; i++) {
        v2 u = p[i], w = p[(i + 1) % n];
        double c = u.x * w.y - w.x * u.y;
        a += c, cx += (u.x + w.x) * c, cy += (u.y + w.y) * c;
    }
    if (centroid && fabs(a) > 0) centroid->x = cx / (3 * a), centroid->y = cy / (3 * a);
    return 0.5 * fabs(a);
}

typedef void (*piece_fn)(void *ctx, uint32_t tri, int x, int y, double atlas_area, v2 centroid);

// Calls fn for every non-empty intersection of triangle `k` (atlas coords)
// with a texel square.
static void raster_tri(const builder *B, const atlas *A, uint32_t k, piece_fn fn, void *ctx) {
    v2 t[3];
    for (int c = 0; c < 3; c++)
        t[c] = (v2){B->uv[k][c][0], B->uv[k][c][1]};
    double ymin = fmin(t[0].y, fmin(t[1].y, t[2].y)), ymax = fmax(t[0].y, fmax(t[1].y, t[2].y));
    int y0 = (int)floor(ymin), y1 = (int)ceil(ymax);
    if (y1 == y0) y1 = y0 + 1;
    if (y0 < 0) y0 = 0;
    if (y1 > A->height) y1 = A->height;
    v2 row[16], tmp[16], cell[16];
    for (int y = y0; y < y1; y++) {
        int n = clip_half(t, 3, 1, y, true, tmp);
        n = clip_half(tmp, n, 1, y + 1, false, row);
        if (n < 3) {
            // A degenerate (line or point) triangle still owns the texel it lies in.
            if (poly_area(t, 3, NULL) == 0 && ymin >= y && ymin < y + 1) {
                int x = (int)floor(fmin(t[0].x, fmin(t[1].x, t[2].x)));
                if (x >= 0 && x < A->width) fn(ctx, k, x, y, 0, t[0]);
            }
            continue;
        }
        double xmin = INFINITY, xmax = -INFINITY;
        for (int i = 0; i < n; i++)
            xmin = fmin(xmin, row[i].x), xmax = fmax(xmax, row[i].x);
        int x0 = (int)floor(xmin), x1 = (int)ceil(xmax);
        if (x1 == x0) x1 = x0 + 1;
        if (x0 < 0) x0 = 0;
        if (x1 > A->width) x1 = A->width;
        for (int x = x0; x < x1; x++) {
            int m = clip_half(row, n, 0, x, true, tmp);
            m = clip_half(tmp, m, 0, x + 1, false, cell);
            if (m < 3) continue;
            v2 cen = {x + 0.5, y + 0.5};
            double a = poly_area(cell, m, &cen);
            if (a > 0) fn(ctx, k, x, y, a, cen);
        }
    }
}

// Is p inside triangle k's atlas footprint by at least `margin` texels?
static bool inside_tri(const builder *B, uint32_t k, double px, double py, double margin) {
    const double(*t)[2] = B->uv[k];
    double area2 =
        (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    if (area2 == 0) return false;
    double sg = area2 > 0 ? 1 : -1;
    for (int e = 0; e < 3; e++) {
        const double *a = t[e], *b = t[(e + 1) % 3];
        double ex = b[0] - a[0], ey = b[1] - a[1], l = sqrt(ex * ex + ey * ey);
        double d = sg * (ex * (py - a[1]) - ey * (px - a[0])) / l;
        if (d < margin) return false;
    }
    return true;
}

static void bary(const builder *B, uint32_t k, v2 p, double *w) {
    const double(*t)[2] = B->uv[k];
    double d =
        (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    if (d == 0) {
        w[0] = 1, w[1] = w[2] = 0;
        return;
    }
    w[1] = ((p.x - t[0][0]) * (t[2][1] - t[0][1]) - (p.y - t[0][1]) * (t[2][0] - t[0][0])) / d;
    w[2] = ((t[1][0] - t[0][0]) * (p.y - t[0][1]) - (t[1][1] - t[0][1]) * (p.x - t[0][0])) / d;
    w[0] = 1 - w[1] - w[2];
}

static void cover_piece(void *vctx, uint32_t k, int x, int y, double a, v2 cen) {
    cover_ctx *c = vctx;
    size_t i = (size_t)y * c->A->width + x;
    const wtri *w = &c->B->tris[k];
    double ta = poly_area((const v2[]){{c->B->uv[k][0][0], c->B->uv[k][0][1]},
                                       {c->B->uv[k][1][0], c->B->uv[k][1][1]},
                                       {c->B->uv[k][2][0], c->B->uv[k][2][1]}},
                          3, NULL);
    if (ta > 0) {
        c->A->area[i] += (float)(a / ta * w->area);
        c->cover[i] += (float)a;
    }
    if (w->area > 0 && a > 0) c->tri_hit[k] = true;
    int ch = c->B->tri_chart[k];
    if (c->chart[i] < 0)
        c->chart[i] = ch;
    else if (c->chart[i] != ch)
        c->conflict[i] = 1;
    if (!c->inside[i] && inside_tri(c->B, k, x + 0.5, y + 0.5, 1e-3)) c->inside[i] = 1;
    (void)cen;
}

static void point_piece(void *vctx, uint32_t k, int x, int y, double a, v2 cen) {
    cover_ctx *c = vctx;
    size_t i = (size_t)y * c->A->width + x;
    int32_t p = c->pidx[i];
    if (p < 0) return;
    double ta = poly_area((const v2[]){{c->B->uv[k][0][0], c->B->uv[k][0][1]},
                                       {c->B->uv[k][1][0], c->B->uv[k][1][1]},
                                       {c->B->uv[k][2][0], c->B->uv[k][2][1]}},
                          3, NULL);
    const wtri *w = &c->B->tris[k];
    double wt = ta > 0 ? a / ta * w->area : 0;
    if (wt <= 0) wt = 1e-30; // degenerate pieces only matter when nothing else covers the texel
    double b[3];
    bary(c->B, k, cen, b);
    for (int r = 0; r < 3; r++)
        b[r] = fmin(fmax(b[r], 0), 1);
    double s = b[0] + b[1] + b[2];
    double *acc = c->acc[p];
    acc[0] += wt;
    for (int r = 0; r < 3; r++) {
        acc[1 + r] += wt * (b[0] * w->p[0][r] + b[1] * w->p[1][r] + b[2] * w->p[2][r]) / s;
        acc[4 + r] += wt * (b[0] * w->nv[0][r] + b[1] * w->nv[1][r] + b[2] * w->nv[2][r]) / s;
    }
    // The side covering most of the texel gives the material.
    if (wt > acc[7]) acc[7] = wt, c->A->points[p].amesh = c->amesh_of_tri[k];
}

void ab_cover_free(cover_ctx *C) {
    free(C->cover);
    free(C->inside);
    free(C->chart);
    free(C->conflict);
    free(C->tri_hit);
    free(C->pidx);
    free(C->acc);
    free(C->amesh_of_tri);
    memset(C, 0, sizeof *C);
}

bool ab_cover(builder *B, atlas *A, cover_ctx *C, bool *folded, st_err *err) {
    size_t ntex = (size_t)A->width * A->height;
    free(A->area);
    free(C->cover);
    free(C->inside);
    free(C->chart);
    free(C->conflict);
    A->area = calloc(ntex, sizeof *A->area);
    C->cover = calloc(ntex, sizeof *C->cover);
    C->inside = calloc(ntex, 1);
    C->chart = malloc(ntex * sizeof *C->chart);
    C->conflict = calloc(ntex, 1);
    if (!A->area || !C->cover || !C->inside || !C->chart || !C->conflict)
        return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory for a %dx%d atlas", A->width,
                       A->height);
    for (size_t i = 0; i < ntex; i++)
        C->chart[i] = -1;
    memset(C->tri_hit, 0, (B->num_tris ? B->num_tris : 1) * sizeof *C->tri_hit);
    for (uint32_t k = 0; k < B->num_tris; k++)
        raster_tri(B, A, k, cover_piece, C);
    *folded = false;
    if (B->o->use_uv1) return true;
    // A chart that folds over itself in the plane (coverage > 1 somewhere).
    bool *bad = calloc(B->num_charts ? (size_t)B->num_charts : 1, sizeof *bad);
    if (!bad) return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    for (size_t i = 0; i < ntex; i++)
        if (C->cover[i] > 1.0f + 1e-4f && C->chart[i] >= 0 && !C->conflict[i])
            bad[C->chart[i]] = true;
    for (uint32_t k = 0; k < B->num_tris; k++)
        if (bad[B->tri_chart[k]] && !B->single[k]) B->single[k] = *folded = true;
    free(bad);
    return true;
}

void ab_invariants(const builder *B, atlas *A, const cover_ctx *C) {
    size_t ntex = (size_t)A->width * A->height;
    for (uint32_t k = 0; k < B->num_tris; k++) {
        A->surface_area += B->tris[k].area;
        if (B->tris[k].area > 1e-14 * B->extent * B->extent && !C->tri_hit[k]) A->uncovered_tris++;
    }
    for (size_t i = 0; i < ntex; i++) {
        A->texel_area_sum += A->area[i];
        if (A->area[i] > 0) A->valid_texels++;
        if (C->conflict[i] || C->cover[i] > 1.0f + 1e-4f) A->overlap_texels++;
    }
}

bool ab_points(builder *B, atlas *A, cover_ctx *C, st_err *err) {
    size_t ntex = (size_t)A->width * A->height;
    C->pidx = malloc(ntex * sizeof *C->pidx);
    if (!C->pidx) return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    int np = 0;
    for (size_t i = 0; i < ntex; i++) {
        bool need = A->area[i] > 0 && !C->inside[i];
        C->pidx[i] = need ? np++ : -1;
    }
    A->points = calloc(np ? (size_t)np : 1, sizeof *A->points);
    C->acc = calloc(np ? (size_t)np : 1, sizeof *C->acc);
    if (!A->points || !C->acc) return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    for (size_t i = 0; i < ntex; i++)
        if (C->pidx[i] >= 0) {
            atlas_point *p = &A->points[C->pidx[i]];
            p->x = (int)(i % A->width), p->y = (int)(i / A->width), p->amesh = -1;
        }
    A->num_points = np;
    for (uint32_t k = 0; k < B->num_tris; k++)
        raster_tri(B, A, k, point_piece, C);
    for (int i = 0; i < np; i++) {
        atlas_point *p = &A->points[i];
        double *acc = C->acc[i], n[3] = {acc[4], acc[5], acc[6]};
        norm3(n);
        for (int r = 0; r < 3; r++)
            p->pos[r] = (float)(acc[1 + r] / acc[0]), p->nrm[r] = (float)n[r];
        if (p->amesh < 0) p->amesh = 0;
    }
    return true;
}
