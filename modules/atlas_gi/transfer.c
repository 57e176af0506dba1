// atlas_gi: precomputed transfer (see transfer.h).
#define _GNU_SOURCE
#include "transfer.h"
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define TR_PI 3.14159265358979323846
#define TR_SPAWN_DEPTH 7 // receiver subtrees at this depth are the threads' tasks

typedef struct texel {
    float p[3], n[3], a;
} texel;

// ---- the cluster tree ----------------------------------------------------------

typedef struct tree_ctx {
    const texel *tx;
    uint32_t *perm;
    float lambda;    // normal scale in the k-d key (m)
    long leaf;       // most texels in a leaf
    float leaf_size; // largest extent of a leaf of several texels (m; 0: any)
} tree_ctx;

// Process CPU time (all threads): under a shared machine's load the wall
// time says little, the CPU time is what the precompute costs.
static double cpu_seconds(void) {
    struct timespec ts;
    return clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) ? 0.0 : ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static float key(const tree_ctx *c, uint32_t slot_texel, int axis) {
    const texel *t = &c->tx[slot_texel];
    return axis < 3 ? t->p[axis] : c->lambda * t->n[axis - 3];
}

// Reorders perm[b, e) so that the k-th is in place and smaller keys precede it.
static void select_kth(const tree_ctx *c, uint32_t *perm, long b, long e, long k, int axis) {
    while (e - b > 1) {
        float pv = key(c, perm[(b + e) / 2], axis);
        long i = b, j = e - 1;
        while (i <= j) {
            while (key(c, perm[i], axis) < pv)
                i++;
            while (key(c, perm[j], axis) > pv)
                j--;
            if (i <= j) {
                uint32_t s = perm[i];
                perm[i] = perm[j], perm[j] = s;
                i++, j--;
            }
        }
        if (k <= j)
            e = j + 1;
        else if (k >= i)
            b = i;
        else
            return;
    }
}

static float angle_between(const float *a, const float *b) {
    float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return acosf(fmaxf(-1.0f, fminf(1.0f, d)));
}

// A leaf is one layer of surface: its texels lie within 0.2 x its size of
// the plane through their centroid along their mean normal (a curved
// surface's sag is far less). Two parallel layers a few centimetres apart
// (a slab's faces; a double-sided closed mesh's back side under its front)
// would otherwise share a leaf, whose links see half their rays blocked.
static bool thin(const tree_ctx *c, const uint32_t *perm, long b, long e, float size) {
    double n[3] = {0, 0, 0}, p[3] = {0, 0, 0}, a = 0;
    for (long s = b; s < e; s++) {
        const texel *x = &c->tx[perm[s]];
        for (int k = 0; k < 3; k++)
            n[k] += x->a * x->n[k], p[k] += x->a * x->p[k];
        a += x->a;
    }
    double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(nl > 0) || !(a > 0)) return true;
    float lo = INFINITY, hi = -INFINITY;
    for (long s = b; s < e; s++) {
        const texel *x = &c->tx[perm[s]];
        float h = 0;
        for (int k = 0; k < 3; k++)
            h += (float)(n[k] / nl) * (x->p[k] - (float)(p[k] / a));
        lo = fminf(lo, h), hi = fmaxf(hi, h);
    }
    return hi - lo <= 0.2f * size;
}

// Splits node i at the median of its widest key axis, unless it is small
// and flat enough for a leaf; children are appended at *count.
static void split_node(transfer *t, const tree_ctx *c, int i, int *count, int *depth) {
    tr_node *nd = &t->nodes[i];
    long b = nd->begin, e = nd->end;
    if (e - b < 2) return;
    float lo[6], hi[6];
    for (int a = 0; a < 6; a++)
        lo[a] = INFINITY, hi[a] = -INFINITY;
    for (long s = b; s < e; s++)
        for (int a = 0; a < 6; a++) {
            float v = key(c, t->perm[s], a);
            lo[a] = fminf(lo[a], v), hi[a] = fmaxf(hi[a], v);
        }
    int axis = 0;
    for (int a = 1; a < 6; a++)
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    // Small enough for a leaf, unless its texels face different ways
    // (a leaf stands for one flat piece of surface).
    float bend = 0;
    for (int a = 3; a < 6; a++)
        bend = fmaxf(bend, hi[a] - lo[a]);
    // A leaf of several texels also stays small in the scene: where the
    // atlas is coarse (a big scene, a small atlas) leaves keep one texel.
    float size = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
    bool small = e - b <= 1 || c->leaf_size <= 0 || size <= c->leaf_size;
    if (e - b <= c->leaf && bend <= 0.3f * c->lambda && small && thin(c, t->perm, b, e, size))
        return;
    long mid = (b + e) / 2;
    select_kth(c, t->perm, b, e, mid, axis);
    int k = *count;
    nd->child = k;
    t->nodes[k] = (tr_node){.child = -1, .parent = i, .begin = (uint32_t)b, .end = (uint32_t)mid};
    t->nodes[k + 1] =
        (tr_node){.child = -1, .parent = i, .begin = (uint32_t)mid, .end = (uint32_t)e};
    depth[k] = depth[k + 1] = depth[i] + 1;
    *count = k + 2;
}

// A leaf's bounds: its texels' area-weighted centroid and mean normal, the
// normal cone and radius; marks its texels' leaf.
static void leaf_bounds(transfer *t, const texel *tx, int i) {
    tr_node *nd = &t->nodes[i];
    double a = 0, cc[3] = {0, 0, 0}, nn[3] = {0, 0, 0};
    for (uint32_t s = nd->begin; s < nd->end; s++) {
        const texel *x = &tx[t->perm[s]];
        a += x->a;
        for (int k = 0; k < 3; k++)
            cc[k] += x->a * x->p[k], nn[k] += x->a * x->n[k];
        t->texel_leaf[t->perm[s]] = i;
    }
    double nl = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    for (int k = 0; k < 3; k++) {
        nd->c[k] = (float)(a > 0 ? cc[k] / a : tx[t->perm[nd->begin]].p[k]);
        nd->n[k] = (float)(nl > 0 ? nn[k] / nl : k == 1);
    }
    nd->area = (float)a;
    nd->cone = nl > 1e-6 * a ? 0.0f : (float)TR_PI;
    nd->rad = 0;
    for (uint32_t s = nd->begin; s < nd->end; s++) {
        const texel *x = &tx[t->perm[s]];
        float d[3] = {x->p[0] - nd->c[0], x->p[1] - nd->c[1], x->p[2] - nd->c[2]};
        nd->rad =
            fmaxf(nd->rad, sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + 0.75f * sqrtf(x->a));
        if (nd->cone < (float)TR_PI) nd->cone = fmaxf(nd->cone, angle_between(nd->n, x->n));
    }
}

// An inner node's bounds from its two children's.
static void inner_bounds(transfer *t, int i) {
    tr_node *nd = &t->nodes[i];
    const tr_node *k0 = &t->nodes[nd->child], *k1 = k0 + 1;
    nd->area = k0->area + k1->area;
    float w0 = nd->area > 0 ? k0->area / nd->area : 0.5f, w1 = 1 - w0, nl = 0;
    for (int a = 0; a < 3; a++) {
        nd->c[a] = w0 * k0->c[a] + w1 * k1->c[a];
        nd->n[a] = k0->area * k0->n[a] + k1->area * k1->n[a];
        nl += nd->n[a] * nd->n[a];
    }
    nl = sqrtf(nl);
    if (nl > 1e-6f * nd->area && nd->area > 0) {
        for (int a = 0; a < 3; a++)
            nd->n[a] /= nl;
        nd->cone = fminf((float)TR_PI, fmaxf(angle_between(nd->n, k0->n) + k0->cone,
                                             angle_between(nd->n, k1->n) + k1->cone));
    } else {
        nd->n[0] = 0, nd->n[1] = 1, nd->n[2] = 0;
        nd->cone = (float)TR_PI;
    }
    nd->rad = 0;
    for (int k = 0; k < 2; k++) {
        const tr_node *ch = k ? k1 : k0;
        float d[3] = {ch->c[0] - nd->c[0], ch->c[1] - nd->c[1], ch->c[2] - nd->c[2]};
        nd->rad = fmaxf(nd->rad, sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + ch->rad);
    }
}

static bool build_tree(transfer *t, const texel *tx, uint32_t n, float extent, long leaf,
                       float leaf_size, st_err *err) {
    t->nodes = calloc(2 * (size_t)n, sizeof *t->nodes);
    int *depth = calloc(2 * (size_t)n, sizeof *depth);
    if (!t->nodes || !depth) {
        free(depth);
        return st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory for %u texels", n);
    }
    tree_ctx c = {tx, t->perm, 0.15f * extent, leaf, leaf_size * extent};
    int count = 1;
    t->nodes[0] = (tr_node){.child = -1, .parent = -1, .begin = 0, .end = n};
    // Breadth first: children are appended, so levels come out contiguous.
    for (int i = 0; i < count; i++)
        split_node(t, &c, i, &count, depth);
    t->num_nodes = count;
    t->num_levels = depth[count - 1] + 1;
    t->level_begin = calloc((size_t)t->num_levels + 1, sizeof *t->level_begin);
    if (!t->level_begin) {
        free(depth);
        return st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory");
    }
    for (int i = count - 1; i >= 0; i--)
        t->level_begin[depth[i]] = i;
    t->level_begin[t->num_levels] = count;
    free(depth);
    // Bounds bottom-up: centroid, area, normal cone, radius.
    for (int i = count - 1; i >= 0; i--) {
        if (t->nodes[i].child < 0)
            leaf_bounds(t, tx, i);
        else
            inner_bounds(t, i);
    }
    return true;
}

// ---- links ---------------------------------------------------------------------

typedef struct tr_link {
    uint32_t r, s;
    float w;
} tr_link;

typedef struct linkbuf {
    tr_link *v;
    size_t n, cap;
    uint64_t rays;
    bool oom;
} linkbuf;

typedef struct task {
    int r;
    int *cand;
    int num;
} task;

typedef struct ctx {
    const transfer *t;
    const texel *tx;
    const texel *ts;  // the texels in slot order: a node's texels are contiguous
    float *cone_cs;   // per node: cos and sin of the normal cone's half-angle
    uint8_t *layered; // per node: its texels lie on more than one layer (not thin)
    const tr_opts *o;
    float cos_cone;
    RTCScene scene;
    task *tasks;
    int num_tasks, task_cap;
    int next_task;
    pthread_mutex_t lock;
    bool oom;
} ctx;

static void push_link(linkbuf *lb, uint32_t r, uint32_t s, float w) {
    if (lb->n == lb->cap) {
        size_t cap = lb->cap ? 2 * lb->cap : 4096;
        tr_link *v = realloc(lb->v, cap * sizeof *v);
        if (!v) {
            lb->oom = true;
            return;
        }
        lb->v = v, lb->cap = cap;
    }
    lb->v[lb->n++] = (tr_link){r, s, w};
}

static bool occluded(const ctx *c, const float *o, const float *q) {
    struct RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    struct RTCRay ray = {0};
    ray.org_x = o[0], ray.org_y = o[1], ray.org_z = o[2];
    ray.dir_x = q[0] - o[0], ray.dir_y = q[1] - o[1], ray.dir_z = q[2] - o[2];
    ray.tnear = 1e-4f, ray.tfar = 1.0f - 1e-4f;
    ray.mask = 0xFFFFFFFFu;
    rtcOccluded1(c->scene, &ic, &ray);
    return ray.tfar < 0;
}

// The link weight: sender area times the area-weighted mean kernel over
// stratified texel pairs, times the fraction of visible pairs. The kernel
// is cheap and takes up to o->kernel pairs; visibility costs a ray and
// takes o->samples of them, spread over the same pairs.
// With may_open, a link whose kernel varies by more than o->spread over its
// pairs (F_max - F_min, the bound on what a bright spot inside the sender
// can get wrong) or whose rays disagree is opened instead: *open is set and
// the weight is not computed (tracing stops at the first disagreement).
static float link_weight(const ctx *c, const tr_node *r, const tr_node *s, linkbuf *lb,
                         bool may_open, bool *open, bool *partial) {
    uint32_t nr = r->end - r->begin, ns = s->end - s->begin;
    uint32_t m = nr > ns ? nr : ns,
             kmax = (uint32_t)(c->o->kernel > c->o->samples ? c->o->kernel : c->o->samples);
    uint32_t kn = m < kmax ? m : kmax;
    uint32_t vn = kn < (uint32_t)c->o->samples ? kn : (uint32_t)c->o->samples;
    *open = *partial = false;
    double sum = 0, asum = 0;
    float klo = INFINITY, khi = 0;
    for (uint32_t i = 0; i < kn; i++) {
        const texel *x = &c->ts[r->begin + (2 * i + 1) * nr / (2 * kn)];
        const texel *y = &c->ts[s->begin + (2 * (kn - 1 - i) + 1) * ns / (2 * kn)];
        asum += y->a;
        float d[3] = {y->p[0] - x->p[0], y->p[1] - x->p[1], y->p[2] - x->p[2]};
        float d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], k = 0;
        if (d2 > 1e-20f) {
            float il = 1.0f / sqrtf(d2);
            float cx = (x->n[0] * d[0] + x->n[1] * d[1] + x->n[2] * d[2]) * il;
            float cy = -(y->n[0] * d[0] + y->n[1] * d[1] + y->n[2] * d[2]) * il;
            if (cx > 0 && cy > 0) k = cx * cy / ((float)TR_PI * d2 + y->a);
        }
        klo = k < klo ? k : klo, khi = k > khi ? k : khi;
        sum += y->a * (double)k * TR_PI;
    }
    if (may_open && c->o->spread > 0 && s->area * (khi - klo) * (float)TR_PI > c->o->spread) {
        *open = true;
        return 0.0f;
    }
    if (!(sum > 0)) return 0.0f;
    // One ray at a time: Embree's rtcOccluded8 on these 2-8 ray packets was
    // 8x slower here (measured on gi_dense), and single rays can stop early.
    int hit = 0, miss = 0;
    if (c->o->visibility)
        for (uint32_t v = 0; v < vn; v++) {
            uint32_t i = (2 * v + 1) * kn / (2 * vn);
            const texel *x = &c->ts[r->begin + (2 * i + 1) * nr / (2 * kn)];
            const texel *y = &c->ts[s->begin + (2 * (kn - 1 - i) + 1) * ns / (2 * kn)];
            float d[3] = {y->p[0] - x->p[0], y->p[1] - x->p[1], y->p[2] - x->p[2]};
            if (x->n[0] * d[0] + x->n[1] * d[1] + x->n[2] * d[2] <= 0 ||
                y->n[0] * d[0] + y->n[1] * d[1] + y->n[2] * d[2] >= 0)
                continue; // the kernel is 0 for this pair: its visibility does not matter
            float off = (float)c->o->offset;
            float a[3], b[3];
            for (int k = 0; k < 3; k++)
                a[k] = x->p[k] + off * x->n[k], b[k] = y->p[k] + off * y->n[k];
            lb->rays++;
            bool blocked = occluded(c, a, b);
            hit += blocked, miss += !blocked;
            if (may_open && hit && miss) break; // it will be opened: the weight is not used
        }
    *partial = hit && miss;
    if (*partial && may_open) {
        *open = true;
        return 0.0f;
    }
    double vis = hit + miss ? (double)miss / (hit + miss) : 1.0;
    return asum > 0 ? (float)(s->area * sum / asum * vis) : 0.0f;
}

enum { L_CULL, L_ACCEPT, L_SPLIT_S, L_SPLIT_R };

// Is the angle between n and w at least pi/2 + cone + beta (every normal of
// the cone faces away from every direction within beta of w)? cs: cos and
// sin of the cone's half-angle; sb, cb: sin and cos of beta. No acos/asin.
static bool faces_away(const float *n, const float *cs, const float *w, float sb, float cb) {
    float cphi = cs[0] * cb - cs[1] * sb; // cos(cone + beta)
    if (cphi <= 0) return false;          // cone + beta >= pi/2: some direction faces
    float sphi = cs[1] * cb + cs[0] * sb;
    return n[0] * w[0] + n[1] * w[1] + n[2] * w[2] <= -sphi;
}

static int classify(const ctx *c, int ri, int si) {
    const tr_node *r = &c->t->nodes[ri], *s = &c->t->nodes[si];
    if (ri == si) return r->child < 0 ? L_CULL : L_SPLIT_R;
    float d[3] = {s->c[0] - r->c[0], s->c[1] - r->c[1], s->c[2] - r->c[2]};
    float dl = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    float rr = r->rad + s->rad;
    bool near = dl < c->o->near_k * rr;
    bool rleaf = r->child < 0, sleaf = s->child < 0;
    if (dl > rr) {
        // Cull when every normal of one cone faces away from every direction
        // between the two bounding spheres.
        float sb = fminf(1.0f, rr / dl), cb = sqrtf(1.0f - sb * sb);
        float w[3] = {d[0] / dl, d[1] / dl, d[2] / dl}, mw[3] = {-w[0], -w[1], -w[2]};
        if (faces_away(r->n, c->cone_cs + 2 * (size_t)ri, w, sb, cb)) return L_CULL;
        if (faces_away(s->n, c->cone_cs + 2 * (size_t)si, mw, sb, cb)) return L_CULL;
    }
    if (rleaf && sleaf) return L_ACCEPT;
    float pd2 = (float)TR_PI * dl * dl;
    bool s_ok = sleaf || (!near && s->area <= c->o->eps * pd2);
    bool r_ok = rleaf || (!near && r->area <= c->o->recv * c->o->eps * pd2 &&
                          r->cone <= c->o->cone_deg * TR_PI / 180);
    if (s_ok && r_ok) return L_ACCEPT;
    if (!s_ok && (r_ok || s->rad >= r->rad)) return L_SPLIT_S;
    return L_SPLIT_R;
}

typedef struct ivec {
    int *v;
    int n, cap;
} ivec;

static bool ipush(ivec *a, int x) {
    if (a->n == a->cap) {
        int cap = a->cap ? 2 * a->cap : 64;
        int *v = realloc(a->v, (size_t)cap * sizeof *v);
        if (!v) return false;
        a->v = v, a->cap = cap;
    }
    a->v[a->n++] = x;
    return true;
}

// Links of receiver r against the candidate senders; what needs a smaller
// receiver goes down to r's children. At spawn depth the rest becomes a task.
static void refine(ctx *c, int r, const int *cand, int num, int depth, bool spawn, linkbuf *lb) {
    const transfer *t = c->t;
    if (spawn && depth == TR_SPAWN_DEPTH) {
        int *copy = malloc((num ? (size_t)num : 1) * sizeof *copy);
        if (!copy || (c->num_tasks == c->task_cap &&
                      !(c->tasks = realloc(c->tasks, (size_t)(c->task_cap = 2 * c->task_cap + 16) *
                                                         sizeof *c->tasks)))) {
            free(copy);
            c->oom = true;
            return;
        }
        memcpy(copy, cand, (size_t)num * sizeof *copy);
        c->tasks[c->num_tasks++] = (task){r, copy, num};
        return;
    }
    ivec stack = {0}, down = {0};
    bool ok = true;
    for (int i = 0; i < num && ok; i++)
        ok = ipush(&stack, cand[i]);
    while (ok && stack.n) {
        int s = stack.v[--stack.n];
        switch (classify(c, r, s)) {
        case L_ACCEPT: {
            const tr_node *rn = &t->nodes[r], *sn = &t->nodes[s];
            // A partly blocked link would smear its shadow over the whole
            // receiver node: open the larger node while it has children
            // and is not too small to matter.
            // A node of two layers (leaves are one) is opened whatever its
            // size: its rays would disagree by layer, not by a shadow.
            bool sopen = sn->child >= 0 &&
                         (sn->end - sn->begin > (uint32_t)c->o->min_split || c->layered[s]);
            bool ropen = rn->child >= 0 &&
                         (rn->end - rn->begin > (uint32_t)c->o->min_split || c->layered[r]);
            bool open = false, partial = false;
            float w = link_weight(c, rn, sn, lb, sopen || ropen, &open, &partial);
            if (open) {
                if (sopen && (!ropen || sn->rad >= rn->rad))
                    ok = ipush(&stack, sn->child) && ipush(&stack, sn->child + 1);
                else
                    ok = ipush(&down, s);
                break;
            }
            if (w > 0) push_link(lb, (uint32_t)r, (uint32_t)s, w);
            break;
        }
        case L_SPLIT_S:
            ok = ipush(&stack, t->nodes[s].child) && ipush(&stack, t->nodes[s].child + 1);
            break;
        case L_SPLIT_R:
            ok = ipush(&down, s);
            break;
        default:
            break;
        }
    }
    if (!ok) lb->oom = true;
    free(stack.v);
    if (ok && down.n && t->nodes[r].child >= 0)
        for (int k = 0; k < 2; k++)
            refine(c, t->nodes[r].child + k, down.v, down.n, depth + 1, spawn, lb);
    free(down.v);
}

typedef struct worker_arg {
    ctx *c;
    linkbuf lb;
} worker_arg;

static void *worker(void *p) {
    worker_arg *wa = p;
    ctx *c = wa->c;
    for (;;) {
        pthread_mutex_lock(&c->lock);
        int k = c->next_task++;
        pthread_mutex_unlock(&c->lock);
        if (k >= c->num_tasks) break;
        task *tk = &c->tasks[k];
        refine(c, tk->r, tk->cand, tk->num, TR_SPAWN_DEPTH, false, &wa->lb);
    }
    return NULL;
}

// Does the ray's direction d meet triangle prim's back (its own normal,
// counter-clockwise seen from its front, points along d)?
static bool back_face(const float *tris, unsigned prim, const float *d) {
    const float *v = tris + 9 * (size_t)prim;
    float e1[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]};
    float e2[3] = {v[6] - v[0], v[7] - v[1], v[8] - v[2]};
    float ng[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    return ng[0] * d[0] + ng[1] * d[1] + ng[2] * d[2] > 0;
}

// An intersect context that ignores one triangle (Embree's context filter).
typedef struct skip_ctx {
    struct RTCIntersectContext ic; // first: Embree passes &ic to the filter
    unsigned skip;
} skip_ctx;

static void skip_filter(const struct RTCFilterFunctionNArguments *a) {
    const skip_ctx *s = (const skip_ctx *)a->context;
    // RTCHitN is SoA: primID is the sixth array of N (rtcore_ray.h's
    // RTCHitN_primID, which is C++ only).
    const unsigned *prim = (const unsigned *)a->hit + 5 * a->N;
    for (unsigned i = 0; i < a->N; i++)
        if (prim[i] == s->skip) a->valid[i] = 0;
}

// What a ray from inside a solid meets first where two solids touch (a
// block standing on a slab) is a pair of coincident faces: the slab's top
// from behind and the block's bottom from the front, and which one Embree
// reports depends on rounding (it changed between CPUs). A front face with
// a back face at the same distance counts as a back face: from outside
// every solid no back face can be met first.
static bool meets_back(const ctx *c, const float *tris, struct RTCRayHit *rh, const float *d) {
    if (back_face(tris, rh->hit.primID, d)) return true;
    float t = rh->ray.tfar, tol = (float)c->o->offset + 1e-4f * t;
    skip_ctx sc;
    rtcInitIntersectContext(&sc.ic);
    sc.ic.filter = skip_filter;
    sc.skip = rh->hit.primID;
    struct RTCRayHit h2 = *rh;
    h2.ray.tnear = t > tol ? t - tol : 0, h2.ray.tfar = t + tol;
    h2.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(c->scene, &sc.ic, &h2);
    return h2.hit.geomID != RTC_INVALID_GEOMETRY_ID && back_face(tris, h2.hit.primID, d);
}

// A texel whose centre lies inside a closed solid (a floor texel under a
// box, a wall's face covered by the next wall box, the back side of a
// double-sided closed mesh) sees only back faces (Unity's backFaceTolerance
// test): four of five rays must meet a back face first and none may escape.
// Its value still reaches the image through the atlas' bilinear filter at
// contact edges, so it borrows the position of a nearby free texel.
static bool buried(const ctx *c, const float *tris, const texel *x) {
    float t[3], b[3];
    float up[3] = {fabsf(x->n[0]) < 0.6f ? 1.0f : 0.0f, fabsf(x->n[0]) < 0.6f ? 0.0f : 1.0f, 0};
    t[0] = up[1] * x->n[2] - up[2] * x->n[1];
    t[1] = up[2] * x->n[0] - up[0] * x->n[2];
    t[2] = up[0] * x->n[1] - up[1] * x->n[0];
    float tl = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int k = 0; k < 3; k++)
        t[k] /= tl;
    b[0] = x->n[1] * t[2] - x->n[2] * t[1];
    b[1] = x->n[2] * t[0] - x->n[0] * t[2];
    b[2] = x->n[0] * t[1] - x->n[1] * t[0];
    static const float dirs[5][3] = {
        {0, 0, 1}, {0.7f, 0, 0.7f}, {-0.7f, 0, 0.7f}, {0, 0.7f, 0.7f}, {0, -0.7f, 0.7f}};
    int back = 0;
    for (int i = 0; i < 5; i++) {
        struct RTCRayHit rh = {0};
        float off = (float)c->o->offset;
        rh.ray.org_x = x->p[0] + off * x->n[0];
        rh.ray.org_y = x->p[1] + off * x->n[1];
        rh.ray.org_z = x->p[2] + off * x->n[2];
        float d[3];
        for (int k = 0; k < 3; k++)
            d[k] = dirs[i][0] * t[k] + dirs[i][1] * b[k] + dirs[i][2] * x->n[k];
        rh.ray.dir_x = d[0], rh.ray.dir_y = d[1], rh.ray.dir_z = d[2];
        rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        struct RTCIntersectContext ic;
        rtcInitIntersectContext(&ic);
        rtcIntersect1(c->scene, &ic, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
        back += meets_back(c, tris, &rh, d);
    }
    return back >= 4;
}

// Per valid atlas cell: -2 free, -1 buried with no free texel to borrow
// from, else the cell whose position and normal a buried texel borrows: the
// nearest free texel of the same orientation within 3 texels in the atlas.
// NULL when out of memory.
static long *find_buried(const ctx *c, const float *tris, const texel *tx, int W, int H) {
    size_t cells = (size_t)W * H;
    long *b = malloc(cells * sizeof *b);
    uint8_t *bur = calloc(cells, 1);
    if (!b || !bur) {
        free(b);
        free(bur);
        return NULL;
    }
    for (size_t i = 0; i < cells; i++)
        bur[i] = tx[i].a > 0 && buried(c, tris, &tx[i]);
    for (size_t id = 0; id < cells; id++) {
        b[id] = -2;
        if (!bur[id]) continue;
        int x0 = (int)(id % (size_t)W), y0 = (int)(id / (size_t)W);
        const texel *me = &tx[id];
        float best = INFINITY;
        long bi = -1;
        for (int dy = -3; dy <= 3; dy++)
            for (int dx = -3; dx <= 3; dx++) {
                int x = x0 + dx, y = y0 + dy;
                if (x < 0 || y < 0 || x >= W || y >= H) continue;
                size_t j = (size_t)y * W + x;
                const texel *o = &tx[j];
                if (bur[j] || !(o->a > 0)) continue;
                if (o->n[0] * me->n[0] + o->n[1] * me->n[1] + o->n[2] * me->n[2] < 0.9f) continue;
                float d[3] = {o->p[0] - me->p[0], o->p[1] - me->p[1], o->p[2] - me->p[2]};
                float d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                if (d2 < best && d2 < 16.0f * me->a) best = d2, bi = (long)j;
            }
        b[id] = bi;
    }
    free(bur);
    return b;
}

static bool make_scene(ctx *c, RTCDevice dev, const float *tris, uint32_t n, st_err *err) {
    c->scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(c->scene, RTC_BUILD_QUALITY_MEDIUM);
    rtcSetSceneFlags(c->scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION); // meets_back
    if (n) {
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                            3 * sizeof(float), 3 * (size_t)n);
        unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                               3 * sizeof(unsigned), n);
        if (!vb || !ib) {
            rtcReleaseGeometry(g);
            return st_fail(err, ST_ERR_RUNTIME, "transfer: embree buffers failed (error %d)",
                           (int)rtcGetDeviceError(dev));
        }
        memcpy(vb, tris, 9 * sizeof(float) * (size_t)n);
        for (uint32_t i = 0; i < 3 * n; i++)
            ib[i] = i;
        rtcCommitGeometry(g);
        rtcAttachGeometry(c->scene, g);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(c->scene);
    if (rtcGetDeviceError(dev) != RTC_ERROR_NONE)
        return st_fail(err, ST_ERR_RUNTIME, "transfer: embree scene build failed (error %d)",
                       (int)rtcGetDeviceError(dev));
    return true;
}

// The texels with area, from the G-buffer's positions and normals (indexed
// by atlas texel); allocates t->perm and t->texel_leaf (-1 everywhere).
static texel *load_texels(transfer *t, const float *pos, const float *nrm, st_err *err) {
    size_t cells = (size_t)t->W * t->H;
    uint32_t n = 0;
    for (size_t i = 0; i < cells; i++)
        n += pos[4 * i + 3] > 0;
    texel *tx = calloc(cells ? cells : 1, sizeof *tx);
    t->perm = malloc((n ? n : 1) * sizeof *t->perm);
    t->texel_leaf = malloc(cells * sizeof *t->texel_leaf);
    if (!tx || !t->perm || !t->texel_leaf) {
        free(tx);
        st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory for a %dx%d atlas", t->W, t->H);
        return NULL;
    }
    for (size_t i = 0; i < cells; i++) {
        t->texel_leaf[i] = -1;
        if (!(pos[4 * i + 3] > 0)) continue;
        texel *x = &tx[i];
        for (int a = 0; a < 3; a++)
            x->p[a] = pos[4 * i + a], x->n[a] = nrm[4 * i + a];
        x->a = pos[4 * i + 3];
    }
    return tx;
}

// The texels that take part, in t->perm: sealed ones (borrow -1) are left
// out, buried ones counted. Returns their number; *extent is their size.
static uint32_t collect_slots(transfer *t, const texel *tx, const long *borrow, float *extent) {
    size_t cells = (size_t)t->W * t->H;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    uint32_t k = 0;
    for (size_t i = 0; i < cells; i++) {
        if (!(tx[i].a > 0)) continue;
        if (borrow && borrow[i] == -1) {
            t->sealed++;
            continue;
        }
        if (borrow && borrow[i] >= 0) t->buried++;
        for (int a = 0; a < 3; a++)
            lo[a] = fminf(lo[a], tx[i].p[a]), hi[a] = fmaxf(hi[a], tx[i].p[a]);
        t->perm[k++] = (uint32_t)i;
    }
    *extent = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
    return k;
}

// What the refinement reads: the texels in slot order (buried ones at their
// borrowed position and normal) and per node its normal cone's cos and sin
// and whether its texels lie on more than one layer.
static bool prepare_links(ctx *c, const texel *tx, const long *borrow, uint32_t n, texel **ts_out,
                          st_err *err) {
    const transfer *t = c->t;
    texel *ts = malloc((size_t)n * sizeof *ts);
    *ts_out = ts;
    c->cone_cs = malloc(2 * (size_t)t->num_nodes * sizeof *c->cone_cs);
    if (!ts || !c->cone_cs)
        return st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory for %u texels", n);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t id = t->perm[i];
        ts[i] = tx[id];
        if (borrow && borrow[id] >= 0)
            for (int a = 0; a < 3; a++)
                ts[i].p[a] = tx[borrow[id]].p[a], ts[i].n[a] = tx[borrow[id]].n[a];
    }
    c->ts = ts;
    c->layered = malloc((size_t)t->num_nodes);
    if (!c->layered) return st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory");
    tree_ctx tc = {.tx = tx, .perm = t->perm};
    for (int i = 0; i < t->num_nodes; i++) {
        const tr_node *nd = &t->nodes[i];
        c->cone_cs[2 * i] = cosf(nd->cone), c->cone_cs[2 * i + 1] = sinf(nd->cone);
        c->layered[i] = !thin(&tc, t->perm, nd->begin, nd->end, 2 * nd->rad);
    }
    return true;
}

// The refinement: the top of the tree serially, then its tasks on `threads`
// threads, each into its own link buffer wa[i].lb.
static void run_refine(ctx *c, worker_arg *wa, int threads) {
    for (int i = 0; i < threads; i++)
        wa[i].c = c;
    int root = 0;
    refine(c, 0, &root, 1, 0, true, &wa[0].lb);
    pthread_t th[64];
    int started = 0;
    for (int i = 1; i < threads && !c->oom; i++)
        if (!pthread_create(&th[started], NULL, worker, &wa[i])) started++;
    worker(&wa[0]);
    for (int i = 0; i < started; i++)
        pthread_join(th[i], NULL);
}

// Gathers every thread's links grouped by receiver: a counting sort. A
// receiver's links all come from one task (or the serial top), in an order
// that does not depend on the thread schedule.
static bool gather_links(transfer *t, const worker_arg *wa, int threads, bool oom, st_err *err) {
    size_t total = 0;
    for (int i = 0; i < threads; i++) {
        total += wa[i].lb.n;
        t->rays += wa[i].lb.rays;
        if (wa[i].lb.oom) oom = true;
    }
    if (oom) return st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory for the links");
    t->link_off = calloc((size_t)t->num_nodes + 1, sizeof *t->link_off);
    t->link_node = malloc((total ? total : 1) * sizeof *t->link_node);
    t->link_w = malloc((total ? total : 1) * sizeof *t->link_w);
    if (!t->link_off || !t->link_node || !t->link_w)
        return st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory for %zu links", total);
    uint32_t *cur = malloc(((size_t)t->num_nodes + 1) * sizeof *cur);
    if (!cur) return st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory");
    for (int i = 0; i < threads; i++)
        for (size_t k = 0; k < wa[i].lb.n; k++)
            t->link_off[wa[i].lb.v[k].r + 1]++;
    for (int i = 0; i < t->num_nodes; i++)
        t->link_off[i + 1] += t->link_off[i];
    memcpy(cur, t->link_off, ((size_t)t->num_nodes + 1) * sizeof *cur);
    for (int i = 0; i < threads; i++)
        for (size_t k = 0; k < wa[i].lb.n; k++) {
            const tr_link *l = &wa[i].lb.v[k];
            uint32_t at = cur[l->r]++;
            t->link_node[at] = l->s;
            t->link_w[at] = l->w;
        }
    free(cur);
    t->num_links = total;
    return true;
}

static void release_ctx(ctx *c, RTCDevice dev) {
    for (int i = 0; i < c->num_tasks; i++)
        free(c->tasks[i].cand);
    free(c->tasks);
    pthread_mutex_destroy(&c->lock);
    if (c->scene) rtcReleaseScene(c->scene);
    if (dev) rtcReleaseDevice(dev);
    free(c->cone_cs);
    free(c->layered);
}

// Tree and links over the n texels in t->perm (the precompute's main part).
static bool build_links(transfer *t, ctx *c, texel *tx, const long *borrow, uint32_t n,
                        float extent, st_err *err) {
    const tr_opts *o = c->o;
    long leaf = o->max_leaves > 0 ? ((long)n + o->max_leaves - 1) / o->max_leaves : 1;
    bool ok = build_tree(t, tx, n, extent > 0 ? extent : 1, leaf, (float)o->leaf_size, err);
    t->leaf_texels = 1;
    for (int i = 0; i < t->num_nodes; i++)
        if (t->nodes[i].child < 0 && (int)(t->nodes[i].end - t->nodes[i].begin) > t->leaf_texels)
            t->leaf_texels = (int)(t->nodes[i].end - t->nodes[i].begin);
    texel *ts = NULL;
    ok = ok && prepare_links(c, tx, borrow, n, &ts, err);
    int threads = o->threads > 0 ? o->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (threads < 1) threads = 1;
    if (threads > 64) threads = 64;
    t->threads = threads;
    worker_arg *wa = calloc((size_t)threads, sizeof *wa);
    if (ok && !wa) ok = st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory");
    if (ok) run_refine(c, wa, threads);
    free(ts);
    ok = ok && gather_links(t, wa, threads, c->oom, err);
    for (int i = 0; i < threads && wa; i++)
        free(wa[i].lb.v);
    free(wa);
    return ok;
}

bool transfer_build(transfer *t, int W, int H, const float *pos, const float *nrm,
                    const float *tris, uint32_t num_tris, const tr_opts *o, st_err *err) {
    memset(t, 0, sizeof *t);
    double c0 = cpu_seconds();
    double t0 = st_now_ms();
    t->W = W, t->H = H;
    texel *tx = load_texels(t, pos, nrm, err);
    if (!tx) return false;
    ctx c = {.t = t, .tx = tx, .o = o};
    pthread_mutex_init(&c.lock, NULL);
    char cfg[32];
    snprintf(cfg, sizeof cfg, "threads=1"); // our own threads trace; no TBB pool
    RTCDevice dev = rtcNewDevice(cfg);
    bool ok = dev && make_scene(&c, dev, tris, num_tris, err);
    if (!dev) st_fail(err, ST_ERR_RUNTIME, "transfer: embree device failed");
    // Buried texels (inside closed solids). One with a free neighbour
    // borrows its position for the links (it reaches the image through the
    // atlas' bilinear filter at contact edges); one without lies deep inside
    // a solid (the back side of a double-sided closed mesh, a face covered
    // by the next box) where nothing sees it and no light reaches it: it
    // takes no part in the transfer (no links, no flux; its value is 0).
    long *borrow = ok && o->visibility ? find_buried(&c, tris, tx, W, H) : NULL;
    if (ok && o->visibility && !borrow)
        ok = st_fail(err, ST_ERR_RUNTIME, "transfer: out of memory");
    float extent = 0;
    uint32_t n = ok ? collect_slots(t, tx, borrow, &extent) : 0;
    if (ok && n) ok = build_links(t, &c, tx, borrow, n, extent, err);
    bool some = n > 0;
    free(borrow);
    release_ctx(&c, dev);
    free(tx);
    if (!ok) return false;
    t->seconds = (st_now_ms() - t0) / 1000;
    if (some) t->cpu_seconds = cpu_seconds() - c0;
    return true;
}

void transfer_free(transfer *t) {
    free(t->nodes);
    free(t->perm);
    free(t->level_begin);
    free(t->texel_leaf);
    free(t->link_off);
    free(t->link_node);
    free(t->link_w);
    memset(t, 0, sizeof *t);
}

uint64_t transfer_bytes(const transfer *t) {
    return (uint64_t)t->num_nodes * sizeof(tr_node) + t->num_links * 8 +
           (uint64_t)t->W * t->H * sizeof(int32_t) + (t->num_nodes + 1) * sizeof(uint32_t) +
           (uint64_t)(t->num_nodes ? t->nodes[0].end : 0) * sizeof(uint32_t);
}
