// Binned-SAH BVH build (see st_bvh.h).
#include "st_bvh.h"
#include "st_gpu.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define BINS 12
#define LEAF 4

typedef struct box {
    float lo[3], hi[3];
} box;

typedef struct build {
    const float *corners;
    uint32_t *idx;
    float (*cen)[3];
    box *tbox;
    float *nodes;
    uint32_t num_nodes, cap;
    int depth;
} build;

static void box_empty(box *b) {
    for (int k = 0; k < 3; k++)
        b->lo[k] = INFINITY, b->hi[k] = -INFINITY;
}
static void box_grow(box *b, const box *o) {
    for (int k = 0; k < 3; k++)
        b->lo[k] = fminf(b->lo[k], o->lo[k]), b->hi[k] = fmaxf(b->hi[k], o->hi[k]);
}
static float box_area(const box *b) {
    float d[3];
    for (int k = 0; k < 3; k++)
        d[k] = fmaxf(b->hi[k] - b->lo[k], 0);
    return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

static void put_node(build *B, uint32_t i, const box *b, int32_t first, int32_t count) {
    float *n = B->nodes + 8 * (size_t)i;
    memcpy(n, b->lo, sizeof b->lo);
    memcpy(n + 4, b->hi, sizeof b->hi);
    memcpy(n + 3, &first, 4);
    memcpy(n + 7, &count, 4);
}

// Builds node `ni` over idx[lo, hi).
static void split(build *B, uint32_t ni, uint32_t lo, uint32_t hi, int depth) {
    if (depth > B->depth) B->depth = depth;
    box b, cb;
    box_empty(&b);
    box_empty(&cb);
    for (uint32_t i = lo; i < hi; i++) {
        box_grow(&b, &B->tbox[B->idx[i]]);
        const float *c = B->cen[B->idx[i]];
        box p = {{c[0], c[1], c[2]}, {c[0], c[1], c[2]}};
        box_grow(&cb, &p);
    }
    uint32_t n = hi - lo;
    if (n <= LEAF || depth >= ST_BVH_MAX_DEPTH - 1) {
        put_node(B, ni, &b, (int32_t)lo, (int32_t)n);
        return;
    }
    // Binned SAH over the axis-aligned centroid bins of all three axes.
    float best = INFINITY;
    int best_axis = -1, best_bin = 0;
    for (int ax = 0; ax < 3; ax++) {
        float ext = cb.hi[ax] - cb.lo[ax];
        if (!(ext > 0)) continue;
        box bins[BINS];
        uint32_t cnt[BINS] = {0};
        for (int k = 0; k < BINS; k++)
            box_empty(&bins[k]);
        for (uint32_t i = lo; i < hi; i++) {
            int k = (int)((B->cen[B->idx[i]][ax] - cb.lo[ax]) / ext * BINS);
            k = k < 0 ? 0 : k >= BINS ? BINS - 1 : k;
            cnt[k]++;
            box_grow(&bins[k], &B->tbox[B->idx[i]]);
        }
        float right_area[BINS];
        uint32_t right_cnt[BINS];
        box acc;
        box_empty(&acc);
        uint32_t c = 0;
        for (int k = BINS - 1; k > 0; k--) {
            box_grow(&acc, &bins[k]);
            c += cnt[k];
            right_area[k] = box_area(&acc);
            right_cnt[k] = c;
        }
        box_empty(&acc);
        c = 0;
        for (int k = 0; k < BINS - 1; k++) {
            box_grow(&acc, &bins[k]);
            c += cnt[k];
            if (!c || !right_cnt[k + 1]) continue;
            float cost = box_area(&acc) * c + right_area[k + 1] * right_cnt[k + 1];
            if (cost < best) best = cost, best_axis = ax, best_bin = k;
        }
    }
    uint32_t mid;
    if (best_axis < 0) {
        mid = lo + n / 2; // all centroids coincide: split the list
    } else {
        float ext = cb.hi[best_axis] - cb.lo[best_axis];
        uint32_t i = lo, j = hi;
        while (i < j) {
            int k = (int)((B->cen[B->idx[i]][best_axis] - cb.lo[best_axis]) / ext * BINS);
            k = k < 0 ? 0 : k >= BINS ? BINS - 1 : k;
            if (k <= best_bin) {
                i++;
            } else {
                uint32_t t = B->idx[i];
                B->idx[i] = B->idx[--j];
                B->idx[j] = t;
            }
        }
        mid = i;
        if (mid == lo || mid == hi) mid = lo + n / 2;
    }
    uint32_t left = B->num_nodes;
    B->num_nodes += 2;
    put_node(B, ni, &b, (int32_t)left, 0);
    split(B, left, lo, mid, depth + 1);
    split(B, left + 1, mid, hi, depth + 1);
}

bool st_bvh_build(st_bvh *out, const float *corners, uint32_t n, st_err *err) {
    memset(out, 0, sizeof *out);
    build B = {.corners = corners};
    size_t cap = 2 * (size_t)(n ? n : 1);
    B.idx = malloc((n ? n : 1) * sizeof *B.idx);
    B.cen = malloc((n ? n : 1) * sizeof *B.cen);
    B.tbox = malloc((n ? n : 1) * sizeof *B.tbox);
    B.nodes = malloc(cap * 8 * sizeof *B.nodes);
    out->tris = malloc((n ? n : 1) * 12 * sizeof *out->tris);
    if (!B.idx || !B.cen || !B.tbox || !B.nodes || !out->tris) {
        free(B.idx), free(B.cen), free(B.tbox), free(B.nodes), free(out->tris);
        out->tris = NULL;
        return st_fail(err, ST_ERR_RUNTIME, "bvh: out of memory for %u triangles", n);
    }
    for (uint32_t i = 0; i < n; i++) {
        const float *c = corners + 9 * (size_t)i;
        B.idx[i] = i;
        box_empty(&B.tbox[i]);
        for (int v = 0; v < 3; v++) {
            box p = {{c[3 * v], c[3 * v + 1], c[3 * v + 2]},
                     {c[3 * v], c[3 * v + 1], c[3 * v + 2]}};
            box_grow(&B.tbox[i], &p);
        }
        for (int k = 0; k < 3; k++)
            B.cen[i][k] = (c[k] + c[3 + k] + c[6 + k]) / 3;
    }
    B.num_nodes = 1;
    if (n) {
        split(&B, 0, 0, n, 1);
    } else {
        // An empty scene: one empty leaf that no ray enters.
        box e;
        box_empty(&e);
        put_node(&B, 0, &e, 0, 0);
        float big = 1e30f;
        for (int k = 0; k < 3; k++)
            B.nodes[k] = big, B.nodes[4 + k] = -big;
        int32_t one = 1;
        memcpy(B.nodes + 7, &one, 4);
    }
    for (uint32_t i = 0; i < n; i++) {
        const float *c = corners + 9 * (size_t)B.idx[i];
        float *t = out->tris + 12 * (size_t)i;
        for (int k = 0; k < 3; k++) {
            t[k] = c[k];
            t[4 + k] = c[3 + k] - c[k];
            t[8 + k] = c[6 + k] - c[k];
        }
        t[3] = t[7] = t[11] = 0;
    }
    out->nodes = B.nodes;
    out->num_nodes = B.num_nodes;
    out->num_tris = n;
    out->depth = B.depth;
    free(B.idx);
    free(B.cen);
    free(B.tbox);
    return true;
}

void st_bvh_free(st_bvh *b) {
    free(b->nodes);
    free(b->tris);
    memset(b, 0, sizeof *b);
}

float *st_bvh_scene_corners(const st_scene *sc, uint32_t *count, st_err *err) {
    size_t n = 0;
    for (int m = 0; m < sc->num_meshes; m++)
        n += sc->meshes[m].num_triangles;
    float *c = malloc((n ? n : 1) * 9 * sizeof *c);
    if (!c) {
        st_fail(err, ST_ERR_RUNTIME, "bvh: out of memory for %zu triangles", n);
        return NULL;
    }
    size_t k = 0;
    for (int m = 0; m < sc->num_meshes; m++) {
        const st_mesh *me = &sc->meshes[m];
        const float *M = me->model; // column-major
        for (uint32_t t = 0; t < me->num_triangles; t++, k++)
            for (int v = 0; v < 3; v++) {
                const float *p = me->positions + 3 * (size_t)me->indices[3 * (size_t)t + v];
                for (int r = 0; r < 3; r++)
                    c[9 * k + 3 * v + r] =
                        M[r] * p[0] + M[4 + r] * p[1] + M[8 + r] * p[2] + M[12 + r];
            }
    }
    *count = (uint32_t)n;
    return c;
}

bool st_bvh_upload(st_bvh_gpu *g, const st_bvh *b, st_err *err) {
    st_bvh_gpu_free(g);
    glCreateBuffers(1, &g->nodes);
    glNamedBufferStorage(g->nodes, (GLsizeiptr)(b->num_nodes * 8 * sizeof(float)), b->nodes, 0);
    glCreateBuffers(1, &g->tris);
    glNamedBufferStorage(
        g->tris, (GLsizeiptr)((b->num_tris ? b->num_tris : 1) * 12 * sizeof(float)), b->tris, 0);
    g->num_tris = b->num_tris;
    g->bytes = ((long long)b->num_nodes * 8 + (b->num_tris ? b->num_tris : 1) * 12LL) * 4;
    return st_gl_check("bvh upload", err);
}

void st_bvh_bind(const st_bvh_gpu *g) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ST_BVH_BINDING_NODES, g->nodes);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ST_BVH_BINDING_TRIS, g->tris);
}

void st_bvh_gpu_free(st_bvh_gpu *g) {
    if (g->nodes) glDeleteBuffers(1, &g->nodes);
    if (g->tris) glDeleteBuffers(1, &g->tris);
    memset(g, 0, sizeof *g);
}
