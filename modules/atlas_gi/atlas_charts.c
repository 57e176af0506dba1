// atlas_gi: world triangles, charts and packing (see atlas.h and
// atlas_builder.h). A generated atlas: charts of edge-connected,
// near-coplanar triangles, projected onto their plane, turned to their
// minimal bounding rectangle and shelf-packed at the largest density that
// fits (or a fixed one); TEXCOORD_1 is taken as it is.
#include "atlas_builder.h"
#include <cglm/cglm.h>
#include <stdlib.h>
#include <string.h>

// ---- world triangles ------------------------------------------------------

bool ab_gather_triangles(builder *B, st_err *err) {
    uint64_t total = 0;
    int nsides = 0;
    for (int m = 0; m < B->num_meshes; m++) {
        if (!B->meshes[m].num_triangles) continue;
        int s = B->meshes[m].double_sided && !B->o->use_uv1 ? 2 : 1;
        nsides += s;
        total += (uint64_t)s * B->meshes[m].num_triangles;
    }
    if (total > UINT32_MAX / 4)
        return st_fail(err, ST_ERR_INPUT, "atlas: too many triangles (%llu)",
                       (unsigned long long)total);
    B->sides = calloc(nsides ? (size_t)nsides : 1, sizeof *B->sides);
    B->tris = malloc((total ? total : 1) * sizeof *B->tris);
    if (!B->sides || !B->tris)
        return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory for %llu triangles",
                       (unsigned long long)total);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    uint32_t t = 0;
    for (int m = 0; m < B->num_meshes; m++) {
        const st_mesh *me = &B->meshes[m];
        if (!me->num_triangles) continue;
        mat4 model, inv; // cglm wants aligned matrices
        memcpy(model, me->model, sizeof model);
        glm_mat4_inv(model, inv);
        double nm[3][3]; // inverse transpose, nm[row][col]
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                nm[r][c] = inv[r][c]; // inv[col][row] transposed
        // TEXCOORD_1 has one texel set per triangle: its back side gets none.
        for (int back = 0; back < (me->double_sided && !B->o->use_uv1 ? 2 : 1); back++) {
            side *sd = &B->sides[B->num_sides++];
            sd->mesh = m;
            sd->back = back;
            sd->first = t;
            sd->count = me->num_triangles;
            for (uint32_t k = 0; k < me->num_triangles; k++, t++) {
                wtri *w = &B->tris[t];
                for (int c = 0; c < 3; c++) {
                    // The back side winds the other way: corners 1 and 2 swap.
                    int cc = back && c ? 3 - c : c;
                    uint32_t v = me->indices[3 * k + cc];
                    const float *p = me->positions + 3 * v, *n = me->normals + 3 * v;
                    for (int r = 0; r < 3; r++) {
                        w->p[c][r] = model[0][r] * p[0] + model[1][r] * p[1] + model[2][r] * p[2] +
                                     model[3][r];
                        w->nv[c][r] =
                            (nm[r][0] * n[0] + nm[r][1] * n[1] + nm[r][2] * n[2]) * (back ? -1 : 1);
                        if (w->p[c][r] < lo[r]) lo[r] = w->p[c][r];
                        if (w->p[c][r] > hi[r]) hi[r] = w->p[c][r];
                    }
                    norm3(w->nv[c]);
                }
                double e1[3], e2[3];
                for (int r = 0; r < 3; r++)
                    e1[r] = w->p[1][r] - w->p[0][r], e2[r] = w->p[2][r] - w->p[0][r];
                cross3(e1, e2, w->n);
                w->area = 0.5 * norm3(w->n);
                if (!isfinite(w->area))
                    return st_fail(err, ST_ERR_INPUT, "atlas: mesh %d has non-finite vertices", m);
            }
        }
    }
    B->num_tris = t;
    B->extent = 0;
    for (int r = 0; r < 3 && t; r++)
        B->extent = fmax(B->extent, hi[r] - lo[r]);
    return true;
}

// ---- charts ---------------------------------------------------------------

typedef struct edge_rec {
    uint64_t key;
    uint32_t tri;
} edge_rec;

static int cmp_edge(const void *a, const void *b) {
    const edge_rec *x = a, *y = b;
    return x->key < y->key ? -1 : x->key > y->key ? 1 : (x->tri > y->tri) - (x->tri < y->tri);
}

typedef struct weld_slot {
    int64_t q[3];
    uint32_t id;
    bool used;
} weld_slot;

// Welds corners of one side by quantized position (split vertices of flat
// shading still connect their triangles) and returns per-corner ids.
static uint32_t *weld_side(const builder *B, const side *sd, double step) {
    size_t nc = (size_t)sd->count * 3, cap = 16;
    while (cap < 2 * nc)
        cap *= 2;
    weld_slot *h = calloc(cap, sizeof *h);
    uint32_t *ids = malloc(nc * sizeof *ids);
    if (!h || !ids) {
        free(h);
        free(ids);
        return NULL;
    }
    uint32_t next = 0;
    for (size_t c = 0; c < nc; c++) {
        const double *p = B->tris[sd->first + c / 3].p[c % 3];
        int64_t q[3];
        uint64_t hash = 1469598103934665603ull;
        for (int r = 0; r < 3; r++) {
            q[r] = (int64_t)llround(p[r] / step);
            hash = (hash ^ (uint64_t)q[r]) * 1099511628211ull;
        }
        size_t i = hash & (cap - 1);
        while (h[i].used && memcmp(h[i].q, q, sizeof q))
            i = (i + 1) & (cap - 1);
        if (!h[i].used) {
            h[i].used = true;
            memcpy(h[i].q, q, sizeof q);
            h[i].id = next++;
        }
        ids[c] = h[i].id;
    }
    free(h);
    return ids;
}

// Convex hull (Andrew's monotone chain) of 2D points in place; returns its size.
static int cmp_pt(const void *a, const void *b) {
    const double *x = a, *y = b;
    return x[0] < y[0] ? -1 : x[0] > y[0] ? 1 : (x[1] > y[1]) - (x[1] < y[1]);
}
static int hull2(double (*p)[2], int n, double (*out)[2]) {
    if (n < 3) {
        memcpy(out, p, (size_t)n * sizeof *p);
        return n;
    }
    qsort(p, (size_t)n, sizeof *p, cmp_pt);
    int k = 0;
    for (int pass = 0; pass < 2; pass++) {
        int start = k;
        for (int i = 0; i < n; i++) {
            const double *q = pass ? p[n - 1 - i] : p[i];
            while (k >= start + 2) {
                double cr = (out[k - 1][0] - out[k - 2][0]) * (q[1] - out[k - 2][1]) -
                            (out[k - 1][1] - out[k - 2][1]) * (q[0] - out[k - 2][0]);
                if (cr > 0) break;
                k--;
            }
            out[k][0] = q[0], out[k][1] = q[1];
            k++;
        }
        k--; // the last point starts the other chain
    }
    return k;
}

// Rotates a chart's corner coordinates to its minimal-area bounding
// rectangle (one side lies on a hull edge), landscape, with its minimum at 0.
static bool orient_chart(builder *B, const uint32_t *tris, int n, chart *ch) {
    int np = 3 * n;
    double(*pts)[2] = malloc((size_t)np * sizeof *pts),
    (*hull)[2] = malloc((size_t)(np + 1) * sizeof *hull);
    if (!pts || !hull) {
        free(pts);
        free(hull);
        return false;
    }
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            memcpy(pts[3 * i + c], B->c2[tris[i]][c], sizeof pts[0]);
    int h = hull2(pts, np, hull);
    double best = INFINITY, bc = 1, bs = 0;
    for (int e = 0; e < h; e++) {
        double dx = hull[(e + 1) % h][0] - hull[e][0], dy = hull[(e + 1) % h][1] - hull[e][1];
        double l = sqrt(dx * dx + dy * dy);
        if (l <= 0) continue;
        double c = dx / l, s = dy / l, mnx = INFINITY, mxx = -INFINITY, mny = INFINITY,
               mxy = -INFINITY;
        for (int i = 0; i < h; i++) {
            double x = c * hull[i][0] + s * hull[i][1], y = -s * hull[i][0] + c * hull[i][1];
            mnx = fmin(mnx, x), mxx = fmax(mxx, x), mny = fmin(mny, y), mxy = fmax(mxy, y);
        }
        double a = (mxx - mnx) * (mxy - mny);
        if (a < best - 1e-12 * fabs(best)) best = a, bc = c, bs = s;
    }
    free(pts);
    free(hull);
    double mnx = INFINITY, mxx = -INFINITY, mny = INFINITY, mxy = -INFINITY;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double *q = B->c2[tris[i]][c], x = bc * q[0] + bs * q[1], y = -bs * q[0] + bc * q[1];
            q[0] = x, q[1] = y;
            mnx = fmin(mnx, x), mxx = fmax(mxx, x), mny = fmin(mny, y), mxy = fmax(mxy, y);
        }
    bool turn = mxy - mny > mxx - mnx; // a quarter turn keeps the orientation
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double *q = B->c2[tris[i]][c], x = q[0] - mnx, y = q[1] - mny;
            if (turn)
                q[0] = (mxy - mny) - y, q[1] = x;
            else
                q[0] = x, q[1] = y;
        }
    ch->w = turn ? mxy - mny : mxx - mnx;
    ch->h = turn ? mxx - mnx : mxy - mny;
    return true;
}

static const wtri *g_sort_tris; // qsort has no context argument in C11
static int cmp_tri_area(const void *a, const void *b) {
    double x = g_sort_tris[*(const uint32_t *)a].area, y = g_sort_tris[*(const uint32_t *)b].area;
    if (x != y) return x > y ? -1 : 1;
    return (*(const uint32_t *)a > *(const uint32_t *)b) -
           (*(const uint32_t *)a < *(const uint32_t *)b);
}

static bool add_chart(builder *B, int side_i, const uint32_t *members, int n, const double *normal,
                      st_err *err) {
    chart *nc = realloc(B->charts, (size_t)(B->num_charts + 1) * sizeof *nc);
    if (!nc) return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    B->charts = nc;
    chart *ch = &B->charts[B->num_charts];
    memset(ch, 0, sizeof *ch);
    ch->side = side_i;
    // Plane basis: t perpendicular to the normal, b = n x t.
    double nn[3] = {normal[0], normal[1], normal[2]}, t[3], b[3];
    if (norm3(nn) == 0) nn[2] = 1;
    double a[3] = {fabs(nn[0]) < 0.6 ? 1 : 0, fabs(nn[0]) < 0.6 ? 0 : 1, 0};
    cross3(a, nn, t);
    norm3(t);
    cross3(nn, t, b);
    for (int i = 0; i < n; i++) {
        uint32_t k = members[i];
        B->tri_chart[k] = B->num_charts;
        for (int c = 0; c < 3; c++) {
            B->c2[k][c][0] = dot3(B->tris[k].p[c], t);
            B->c2[k][c][1] = dot3(B->tris[k].p[c], b);
        }
    }
    if (!orient_chart(B, members, n, ch))
        return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    B->num_charts++;
    return true;
}

// Adjacency (CSR) of one side's n triangles from their welded corner ids:
// triangles sharing an edge are neighbours. False when out of memory.
static bool side_adjacency(const uint32_t *ids, uint32_t n, uint32_t *adj_start,
                           uint32_t **adj_out) {
    edge_rec *edges = malloc((size_t)n * 3 * sizeof *edges);
    if (!edges) return false;
    for (uint32_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++) {
            uint64_t a = ids[3 * k + c], b = ids[3 * k + (c + 1) % 3];
            edges[3 * k + c].key = a < b ? a << 32 | b : b << 32 | a;
            edges[3 * k + c].tri = k;
        }
    qsort(edges, (size_t)n * 3, sizeof *edges, cmp_edge);
    size_t ne = (size_t)n * 3;
    uint32_t *adj = NULL;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            for (uint32_t k = 0; k < n; k++)
                adj_start[k + 1] += adj_start[k];
            adj = malloc((adj_start[n] ? adj_start[n] : 1) * sizeof *adj);
        }
        uint32_t *fill = pass ? calloc(n, sizeof *fill) : NULL;
        if (pass && (!adj || !fill)) {
            free(fill);
            free(adj);
            free(edges);
            return false;
        }
        for (size_t i = 0; i < ne;) {
            size_t j = i;
            while (j < ne && edges[j].key == edges[i].key)
                j++;
            if (edges[i].key >> 32 != (edges[i].key & 0xffffffffu)) // not a collapsed edge
                for (size_t x = i; x < j; x++)
                    for (size_t y = i; y < j; y++) {
                        if (edges[x].tri == edges[y].tri) continue;
                        uint32_t tx = edges[x].tri;
                        if (!pass)
                            adj_start[tx + 1]++;
                        else
                            adj[adj_start[tx] + fill[tx]++] = edges[y].tri;
                    }
            i = j;
        }
        free(fill);
    }
    free(edges);
    *adj_out = adj;
    return true;
}

// Grows one chart from `seed` over neighbours (breadth first, into queue)
// whose normals stay within the angle of the seed's; returns its size.
static uint32_t grow_chart(builder *B, const side *sd, uint32_t seed, const uint32_t *adj_start,
                           const uint32_t *adj, uint32_t *queue) {
    double cos_max = cos(B->o->chart_angle_deg * 3.14159265358979323846 / 180.0);
    double tiny = 1e-14 * B->extent * B->extent;
    const double *cn = B->tris[seed].n;
    uint32_t qn = 0, qh = 0;
    queue[qn++] = seed;
    B->tri_chart[seed] = -2; // claimed
    if (B->single[seed]) return qn;
    while (qh < qn) {
        uint32_t k = queue[qh++] - sd->first;
        for (uint32_t a = adj_start[k]; a < adj_start[k + 1]; a++) {
            uint32_t g = sd->first + adj[a];
            if (B->tri_chart[g] != -1 || B->single[g]) continue;
            const wtri *w = &B->tris[g];
            // Degenerate triangles join any neighbour: they have no area to distort.
            if (w->area > tiny && dot3(w->n, cn) < cos_max) continue;
            B->tri_chart[g] = -2;
            queue[qn++] = g;
        }
    }
    return qn;
}

// Grows charts over edge-connected triangles of one side whose normals stay
// within the angle of the seed's (largest first).
static bool chart_side(builder *B, int si, st_err *err) {
    const side *sd = &B->sides[si];
    uint32_t n = sd->count;
    double step = fmax(B->extent, 1e-30) * 1e-7;
    uint32_t *ids = weld_side(B, sd, step);
    uint32_t *order = malloc((size_t)n * sizeof *order), *queue = malloc((size_t)n * sizeof *queue);
    uint32_t *adj_start = calloc((size_t)n + 1, sizeof *adj_start), *adj = NULL;
    bool ok = ids && order && queue && adj_start && side_adjacency(ids, n, adj_start, &adj);
    if (!ok) goto done;
    for (uint32_t k = 0; k < n; k++)
        order[k] = sd->first + k;
    g_sort_tris = B->tris;
    qsort(order, n, sizeof *order, cmp_tri_area);
    for (uint32_t oi = 0; oi < n && ok; oi++) {
        uint32_t seed = order[oi];
        if (B->tri_chart[seed] >= 0) continue;
        uint32_t qn = grow_chart(B, sd, seed, adj_start, adj, queue);
        ok = add_chart(B, si, queue, (int)qn, B->tris[seed].n, err);
    }
done:
    if (!ok && err->kind == ST_ERR_NONE)
        st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory charting %u triangles", n);
    free(ids);
    free(order);
    free(queue);
    free(adj_start);
    free(adj);
    return ok;
}
// ---- packing --------------------------------------------------------------

static const chart *g_sort_charts;
static int cmp_chart(const void *a, const void *b) {
    const chart *x = &g_sort_charts[*(const int *)a], *y = &g_sort_charts[*(const int *)b];
    if (x->ht != y->ht) return y->ht - x->ht;
    if (x->wt != y->wt) return y->wt - x->wt;
    return *(const int *)a - *(const int *)b;
}

// Shelf packing at density s (texels per metre): tallest charts first, rows
// left to right. Returns whether everything fits into W x H.
static bool pack(builder *B, double s, int W, int H, int *order) {
    int g = B->o->gutter;
    for (int i = 0; i < B->num_charts; i++) {
        chart *c = &B->charts[i];
        double w = ceil(c->w * s - 1e-9), h = ceil(c->h * s - 1e-9);
        if (w > W || h > H) return false;
        c->wt = (int)fmax(w, 1) + 2 * g;
        c->ht = (int)fmax(h, 1) + 2 * g;
        order[i] = i;
    }
    g_sort_charts = B->charts;
    qsort(order, (size_t)B->num_charts, sizeof *order, cmp_chart);
    int x = 0, y = 0, shelf = 0;
    for (int i = 0; i < B->num_charts; i++) {
        chart *c = &B->charts[order[i]];
        if (c->wt > W) return false;
        if (x + c->wt > W) y += shelf, x = 0, shelf = 0;
        c->x0 = x, c->y0 = y;
        x += c->wt;
        if (c->ht > shelf) shelf = c->ht;
        if (y + shelf > H) return false;
    }
    return true;
}

static bool layout(builder *B, atlas *A, st_err *err) {
    int *order = malloc((B->num_charts ? (size_t)B->num_charts : 1) * sizeof *order);
    if (!order) return st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
    double proj_area = 0;
    for (int i = 0; i < B->num_charts; i++)
        proj_area += B->charts[i].w * B->charts[i].h;
    bool ok = false;
    double s = 0;
    int W = B->o->size, H = B->o->size;
    if (B->o->texels_per_meter > 0) {
        s = B->o->texels_per_meter;
        for (W = 64; W <= B->o->max_size && !ok; W *= 2) {
            H = W;
            ok = pack(B, s, W, H, order);
            if (ok) break;
        }
        if (!ok)
            st_fail(err, ST_ERR_INPUT,
                    "atlas: %g texels per metre does not fit %d charts into %dx%d; lower "
                    "texels_per_meter",
                    s, B->num_charts, B->o->max_size, B->o->max_size);
    } else if (!pack(B, 0, W, H, order)) {
        st_fail(
            err, ST_ERR_INPUT,
            "atlas: %d charts do not fit into %dx%d even at the smallest density; raise atlas_size",
            B->num_charts, W, H);
    } else {
        // The largest density that still packs (bisection; packing is monotone
        // in practice, the last fitting value is kept).
        double lo = 0, hi = proj_area > 0 ? sqrt((double)W * H / proj_area) * 1.01 : 1.0;
        for (int it = 0; it < 64 && pack(B, hi, W, H, order); it++)
            lo = hi, hi *= 2;
        for (int it = 0; it < 40; it++) {
            double mid = 0.5 * (lo + hi);
            if (pack(B, mid, W, H, order))
                lo = mid;
            else
                hi = mid;
        }
        s = lo;
        ok = pack(B, s, W, H, order);
        if (!ok) st_fail(err, ST_ERR_RUNTIME, "atlas: packing failed");
    }
    free(order);
    if (!ok) return false;
    A->width = W, A->height = H;
    A->texels_per_meter = s;
    int g = B->o->gutter;
    for (uint32_t k = 0; k < B->num_tris; k++) {
        const chart *c = &B->charts[B->tri_chart[k]];
        for (int v = 0; v < 3; v++) {
            B->uv[k][v][0] = c->x0 + g + B->c2[k][v][0] * s;
            B->uv[k][v][1] = c->y0 + g + B->c2[k][v][1] * s;
        }
    }
    return true;
}

// Charts every side (or takes TEXCOORD_1) and lays the atlas out.
bool ab_make_layout(builder *B, atlas *A, st_err *err) {
    free(B->charts);
    B->charts = NULL;
    B->num_charts = 0;
    if (B->o->use_uv1) {
        A->width = A->height = B->o->size;
        A->texels_per_meter = 0;
        for (int si = 0; si < B->num_sides; si++) {
            const side *sd = &B->sides[si];
            const st_mesh *m = &B->meshes[sd->mesh];
            for (uint32_t k = 0; k < sd->count; k++) {
                B->tri_chart[sd->first + k] = si;
                for (int c = 0; c < 3; c++) {
                    int cc = sd->back && c ? 3 - c : c;
                    uint32_t v = m->indices[3 * k + cc];
                    B->uv[sd->first + k][c][0] = (double)m->uv1[2 * v] * A->width;
                    B->uv[sd->first + k][c][1] = (double)m->uv1[2 * v + 1] * A->height;
                }
            }
        }
        B->num_charts = B->num_sides;
        return true;
    }
    for (uint32_t k = 0; k < B->num_tris; k++)
        B->tri_chart[k] = -1;
    for (int si = 0; si < B->num_sides; si++)
        if (!chart_side(B, si, err)) return false;
    return layout(B, A, err);
}
