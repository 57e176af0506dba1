// atlas_gi: atlas generation and exact texel coverage (see atlas.h).
#include "atlas.h"
#include <cglm/cglm.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

// One triangle of one side, in world space.
typedef struct wtri {
    double p[3][3];  // corners
    double nv[3][3]; // world vertex normals
    double n[3];     // unit geometric normal (0 when degenerate)
    double area;     // m^2
} wtri;

typedef struct side {
    int mesh;
    bool back;
    uint32_t first, count; // triangles in the global list
} side;

typedef struct chart {
    int side;
    double w, h; // extent in metres after rotation
    int x0, y0;  // packed position: lower left of the padded rectangle (texels)
    int wt, ht;  // padded size in texels
} chart;

typedef struct builder {
    const st_mesh *meshes;
    int num_meshes;
    const atlas_opts *o;
    side *sides;
    int num_sides;
    wtri *tris;
    uint32_t num_tris;
    double extent;
    int32_t *tri_chart;
    double (*c2)[3][2]; // per corner: chart-plane coordinates (m)
    double (*uv)[3][2]; // per corner: atlas coordinates (texels)
    chart *charts;
    int num_charts;
    bool *single; // triangles forced into charts of their own (their chart folded)
} builder;

static inline double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void cross3(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static inline double norm3(double *v) {
    double l = sqrt(dot3(v, v));
    if (l > 0)
        for (int k = 0; k < 3; k++)
            v[k] /= l;
    return l;
}

bool atlas_meshes_have_uv1(const st_mesh *meshes, int n) {
    int with_tris = 0;
    for (int i = 0; i < n; i++) {
        if (!meshes[i].num_triangles) continue;
        with_tris++;
        if (!meshes[i].uv1) return false;
    }
    return with_tris > 0;
}

// ---- world triangles ------------------------------------------------------

static bool gather_triangles(builder *B, st_err *err) {
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

// Grows charts over edge-connected triangles of one side whose normals stay
// within the angle of the seed's (largest first).
static bool chart_side(builder *B, int si, st_err *err) {
    const side *sd = &B->sides[si];
    uint32_t n = sd->count;
    double step = fmax(B->extent, 1e-30) * 1e-7;
    uint32_t *ids = weld_side(B, sd, step);
    edge_rec *edges = malloc((size_t)n * 3 * sizeof *edges);
    uint32_t *order = malloc((size_t)n * sizeof *order), *queue = malloc((size_t)n * sizeof *queue);
    uint32_t *adj_start = calloc((size_t)n + 1, sizeof *adj_start), *adj = NULL;
    bool ok = ids && edges && order && queue && adj_start;
    if (!ok) goto done;
    for (uint32_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++) {
            uint64_t a = ids[3 * k + c], b = ids[3 * k + (c + 1) % 3];
            edges[3 * k + c].key = a < b ? a << 32 | b : b << 32 | a;
            edges[3 * k + c].tri = k;
        }
    qsort(edges, (size_t)n * 3, sizeof *edges, cmp_edge);
    // Adjacency (CSR): triangles sharing an edge key are neighbours.
    size_t ne = (size_t)n * 3, nadj = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            for (uint32_t k = 0; k < n; k++)
                adj_start[k + 1] += adj_start[k];
            adj = malloc((adj_start[n] ? adj_start[n] : 1) * sizeof *adj);
            if (!adj) {
                ok = false;
                goto done;
            }
            nadj = 0;
        }
        uint32_t *fill = pass ? calloc(n, sizeof *fill) : NULL;
        if (pass && !fill) {
            ok = false;
            goto done;
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
                            adj[adj_start[tx] + fill[tx]++] = edges[y].tri, nadj++;
                    }
            i = j;
        }
        free(fill);
    }
    for (uint32_t k = 0; k < n; k++)
        order[k] = sd->first + k;
    g_sort_tris = B->tris;
    qsort(order, n, sizeof *order, cmp_tri_area);
    double cos_max = cos(B->o->chart_angle_deg * 3.14159265358979323846 / 180.0);
    double tiny = 1e-14 * B->extent * B->extent;
    for (uint32_t oi = 0; oi < n && ok; oi++) {
        uint32_t seed = order[oi];
        if (B->tri_chart[seed] >= 0) continue;
        const double *cn = B->tris[seed].n;
        uint32_t qn = 0, qh = 0;
        queue[qn++] = seed;
        B->tri_chart[seed] = -2; // claimed
        if (!B->single[seed]) {
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
        }
        ok = add_chart(B, si, queue, (int)qn, cn, err);
    }
    (void)nadj;
done:
    if (!ok && err->kind == ST_ERR_NONE)
        st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory charting %u triangles", n);
    free(ids);
    free(edges);
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

// ---- exact coverage ---------------------------------------------------------

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

typedef struct cover_ctx {
    builder *B;
    atlas *A;
    float *cover;      // atlas-space coverage per texel (1 = full)
    uint8_t *inside;   // a triangle's rasterizer covers the centre
    int32_t *chart;    // owner chart per texel
    uint8_t *conflict; // texel claimed by two charts
    bool *tri_hit;
    // pass 2
    int32_t *pidx;
    double (*acc)[8]; // per point: weight, position, normal, heaviest piece
    int32_t *amesh_of_tri;
} cover_ctx;

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

// Charts every side (or takes TEXCOORD_1) and lays the atlas out.
static bool make_layout(builder *B, atlas *A, st_err *err) {
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

bool atlas_build(atlas *A, const st_mesh *meshes, int num_meshes, const atlas_opts *o,
                 st_err *err) {
    memset(A, 0, sizeof *A);
    builder B = {.meshes = meshes, .num_meshes = num_meshes, .o = o};
    cover_ctx C = {0};
    bool ok = false;
    if (o->gutter < 1 || o->size < 1 || o->max_size < 1) {
        st_fail(err, ST_ERR_INPUT, "atlas: bad options");
        goto done;
    }
    if (o->use_uv1 && !atlas_meshes_have_uv1(meshes, num_meshes)) {
        st_fail(err, ST_ERR_INPUT, "atlas: not every mesh has TEXCOORD_1");
        goto done;
    }
    if (!gather_triangles(&B, err)) goto done;
    size_t nt = B.num_tris ? B.num_tris : 1;
    B.tri_chart = malloc(nt * sizeof *B.tri_chart);
    B.c2 = malloc(nt * sizeof *B.c2);
    B.uv = malloc(nt * sizeof *B.uv);
    B.single = calloc(nt, sizeof *B.single);
    C.tri_hit = calloc(nt, sizeof *C.tri_hit);
    C.amesh_of_tri = malloc(nt * sizeof *C.amesh_of_tri);
    if (!B.tri_chart || !B.c2 || !B.uv || !B.single || !C.tri_hit || !C.amesh_of_tri) {
        st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
        goto done;
    }
    for (int si = 0; si < B.num_sides; si++)
        for (uint32_t k = 0; k < B.sides[si].count; k++)
            C.amesh_of_tri[B.sides[si].first + k] = si;
    C.B = &B;
    C.A = A;
    // A chart that folds over itself in the plane (coverage > 1 somewhere) is
    // split into single triangles and the layout redone.
    for (int attempt = 0; attempt < 3; attempt++) {
        if (!make_layout(&B, A, err)) goto done;
        size_t ntex = (size_t)A->width * A->height;
        free(A->area);
        free(C.cover);
        free(C.inside);
        free(C.chart);
        free(C.conflict);
        A->area = calloc(ntex, sizeof *A->area);
        C.cover = calloc(ntex, sizeof *C.cover);
        C.inside = calloc(ntex, 1);
        C.chart = malloc(ntex * sizeof *C.chart);
        C.conflict = calloc(ntex, 1);
        if (!A->area || !C.cover || !C.inside || !C.chart || !C.conflict) {
            st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory for a %dx%d atlas", A->width,
                    A->height);
            goto done;
        }
        for (size_t i = 0; i < ntex; i++)
            C.chart[i] = -1;
        memset(C.tri_hit, 0, nt * sizeof *C.tri_hit);
        for (uint32_t k = 0; k < B.num_tris; k++)
            raster_tri(&B, A, k, cover_piece, &C);
        bool folded = false;
        if (!o->use_uv1) {
            bool *bad = calloc(B.num_charts ? (size_t)B.num_charts : 1, sizeof *bad);
            if (!bad) {
                st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
                goto done;
            }
            for (size_t i = 0; i < ntex; i++)
                if (C.cover[i] > 1.0f + 1e-4f && C.chart[i] >= 0 && !C.conflict[i])
                    bad[C.chart[i]] = true;
            for (uint32_t k = 0; k < B.num_tris; k++)
                if (bad[B.tri_chart[k]] && !B.single[k]) B.single[k] = folded = true;
            free(bad);
        }
        if (!folded) break;
    }
    size_t ntex = (size_t)A->width * A->height;
    // Invariants.
    for (uint32_t k = 0; k < B.num_tris; k++) {
        A->surface_area += B.tris[k].area;
        if (B.tris[k].area > 1e-14 * B.extent * B.extent && !C.tri_hit[k]) A->uncovered_tris++;
    }
    for (size_t i = 0; i < ntex; i++) {
        A->texel_area_sum += A->area[i];
        if (A->area[i] > 0) A->valid_texels++;
        if (C.conflict[i] || C.cover[i] > 1.0f + 1e-4f) A->overlap_texels++;
    }
    // Texels no rasterizer sample would reach become points.
    C.pidx = malloc(ntex * sizeof *C.pidx);
    if (!C.pidx) {
        st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
        goto done;
    }
    int np = 0;
    for (size_t i = 0; i < ntex; i++) {
        bool need = A->area[i] > 0 && !C.inside[i];
        C.pidx[i] = need ? np++ : -1;
    }
    A->points = calloc(np ? (size_t)np : 1, sizeof *A->points);
    C.acc = calloc(np ? (size_t)np : 1, sizeof *C.acc);
    if (!A->points || !C.acc) {
        st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
        goto done;
    }
    for (size_t i = 0; i < ntex; i++)
        if (C.pidx[i] >= 0) {
            atlas_point *p = &A->points[C.pidx[i]];
            p->x = (int)(i % A->width), p->y = (int)(i / A->width), p->amesh = -1;
        }
    A->num_points = np;
    for (uint32_t k = 0; k < B.num_tris; k++)
        raster_tri(&B, A, k, point_piece, &C);
    for (int i = 0; i < np; i++) {
        atlas_point *p = &A->points[i];
        double *acc = C.acc[i], n[3] = {acc[4], acc[5], acc[6]};
        norm3(n);
        for (int r = 0; r < 3; r++)
            p->pos[r] = (float)(acc[1 + r] / acc[0]), p->nrm[r] = (float)n[r];
        if (p->amesh < 0) p->amesh = 0;
    }
    // Split meshes, the triangle table and per-mesh bases.
    A->num_charts = B.num_charts;
    A->meshes = calloc(B.num_sides ? (size_t)B.num_sides : 1, sizeof *A->meshes);
    A->tris = malloc(nt * 16 * sizeof *A->tris);
    A->lookup = malloc(nt * 12 * sizeof *A->lookup);
    A->mesh_base = malloc((num_meshes ? (size_t)num_meshes : 1) * 2 * sizeof *A->mesh_base);
    if (!A->meshes || !A->tris || !A->lookup || !A->mesh_base) {
        st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
        goto done;
    }
    for (int m = 0; m < 2 * num_meshes; m++)
        A->mesh_base[m] = -1;
    for (int si = 0; si < B.num_sides; si++) {
        if (!build_side_mesh(&B, A, si, &A->meshes[si])) {
            st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
            goto done;
        }
        A->num_meshes++;
        A->mesh_base[2 * B.sides[si].mesh + B.sides[si].back] = (int32_t)B.sides[si].first;
    }
    A->num_tris = B.num_tris;
    for (uint32_t k = 0; k < B.num_tris; k++) {
        const wtri *w = &B.tris[k];
        float *t = A->tris + 16 * (size_t)k;
        for (int r = 0; r < 3; r++) {
            t[r] = (float)w->p[0][r];
            t[4 + r] = (float)(w->p[1][r] - w->p[0][r]);
            t[8 + r] = (float)(w->p[2][r] - w->p[0][r]);
        }
        t[3] = (float)(B.uv[k][0][0] / A->width);
        t[7] = (float)(B.uv[k][0][1] / A->height);
        t[11] = (float)(B.uv[k][1][0] / A->width);
        t[12] = (float)(B.uv[k][1][1] / A->height);
        t[13] = (float)(B.uv[k][2][0] / A->width);
        t[14] = (float)(B.uv[k][2][1] / A->height);
        t[15] = 0;
        // Gradients of u and v in the triangle's plane: g = a e1 + b e2 with
        // g . e1 = du1, g . e2 = du2.
        double e1[3], e2[3];
        for (int r = 0; r < 3; r++)
            e1[r] = w->p[1][r] - w->p[0][r], e2[r] = w->p[2][r] - w->p[0][r];
        double a11 = dot3(e1, e1), a12 = dot3(e1, e2), a22 = dot3(e2, e2),
               det = a11 * a22 - a12 * a12;
        float *L = A->lookup + 12 * (size_t)k;
        for (int c = 0; c < 2; c++) {
            double scale = c ? A->height : A->width;
            double d1 = (B.uv[k][1][c] - B.uv[k][0][c]) / scale,
                   d2 = (B.uv[k][2][c] - B.uv[k][0][c]) / scale;
            double ca = 0, cb = 0;
            if (det > 1e-30 * a11 * a22)
                ca = (a22 * d1 - a12 * d2) / det, cb = (a11 * d2 - a12 * d1) / det;
            for (int r = 0; r < 3; r++)
                L[4 * (c + 1) + r] = (float)(ca * e1[r] + cb * e2[r]);
        }
        for (int r = 0; r < 3; r++)
            L[r] = (float)w->p[0][r];
        L[3] = (float)(B.uv[k][0][0] / A->width);
        L[7] = (float)(B.uv[k][0][1] / A->height);
        L[11] = 0;
    }
    if (o->keep_chart_map) {
        A->chart = C.chart;
        C.chart = NULL;
        A->chart_mesh = malloc((B.num_charts ? (size_t)B.num_charts : 1) * sizeof *A->chart_mesh);
        if (!A->chart_mesh) {
            st_fail(err, ST_ERR_RUNTIME, "atlas: out of memory");
            goto done;
        }
        for (int i = 0; i < B.num_charts; i++)
            A->chart_mesh[i] = B.sides[o->use_uv1 ? i : B.charts[i].side].mesh;
    }
    ok = true;
done:
    free(C.cover);
    free(C.inside);
    free(C.chart);
    free(C.conflict);
    free(C.tri_hit);
    free(C.pidx);
    free(C.acc);
    free(C.amesh_of_tri);
    builder_free(&B);
    if (!ok) atlas_free(A);
    return ok;
}
