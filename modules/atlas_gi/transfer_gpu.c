// atlas_gi: the precomputed transfer on the GPU (transfer_gpu.h).
#include "transfer_gpu.h"
#include "st_gpu.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tr_gpu_tangents(const tr_node *n, double t1[3], double t2[3]) {
    double m[3] = {n->n[0], n->n[1], n->n[2]};
    double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    double z[3] = {0, 0, 1};
    if (l > 0) z[0] = m[0] / l, z[1] = m[1] / l, z[2] = m[2] / l;
    double a[3] = {fabs(z[0]) < 0.6 ? 1 : 0, fabs(z[0]) < 0.6 ? 0 : 1, 0};
    double az = a[0] * z[0] + a[1] * z[1];
    for (int i = 0; i < 3; i++)
        t1[i] = a[i] - az * z[i];
    double tl = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int i = 0; i < 3; i++)
        t1[i] /= tl;
    t2[0] = z[1] * t1[2] - z[2] * t1[1];
    t2[1] = z[2] * t1[0] - z[0] * t1[2];
    t2[2] = z[0] * t1[1] - z[1] * t1[0];
}

// A link's record, given its receiver's tangents (the upload computes them
// once per node, not once per link).
static void pack_link(const transfer *t, int receiver, uint64_t k, const double t1[3],
                      const double t2[3], uint32_t out[4]) {
    const tr_node *r = &t->nodes[receiver], *s = &t->nodes[t->link_node[k]];
    float w = s->area > 0 ? t->link_w[k] / s->area : 0.0f;
    // grad_x ln(cos_x cos_j / d^2) at the centroids, d = y - x: terms whose
    // cosine is not well defined (a curved node) are left out, and only a
    // flat receiver gets a gradient at all; its texels lie in its plane, so
    // the gradient is stored along the plane's tangents.
    double d[3] = {s->c[0] - r->c[0], s->c[1] - r->c[1], s->c[2] - r->c[2]};
    double d2 = fmax(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], 1e-12), dl = sqrt(d2);
    double g[3] = {0, 0, 0};
    if (cos(r->cone) > 0.9) {
        double cr = r->n[0] * d[0] + r->n[1] * d[1] + r->n[2] * d[2];
        double cs = -(s->n[0] * d[0] + s->n[1] * d[1] + s->n[2] * d[2]);
        for (int i = 0; i < 3; i++) {
            g[i] = 4.0 * d[i] / d2;
            if (cr > 1e-3 * dl) g[i] -= r->n[i] / cr;
            if (cos(s->cone) > 0.9 && cs > 0.2 * dl) g[i] += s->n[i] / cs;
        }
    }
    // The first-order term stands for the kernel only while the kernel is
    // near linear over the receiver node. Across a crease or a contact the
    // sender lies close to the receiver's plane: cos_x changes by a large
    // fraction of itself over the node (rad / (n . d) large) and the term
    // overshot, by 50-70 % on the crease under ds_cornell_front's light
    // (issue 34); there the node's mean, which the link's weight already is,
    // stands alone. A bound on |g| rad instead (the full gradient) met the
    // crease as well but also dropped the term for senders high above a
    // large receiver, where it is right: test_atlas_gi_transfer's disk
    // oracle fell 2 % short.
    double cr = r->n[0] * d[0] + r->n[1] * d[1] + r->n[2] * d[2];
    if (r->rad > TR_GPU_GRAD_MAX * fmax(cr, 0.0)) g[0] = g[1] = g[2] = 0;
    out[0] = t->link_node[k];
    memcpy(&out[1], &w, 4);
    float gt[2] = {(float)(g[0] * t1[0] + g[1] * t1[1] + g[2] * t1[2]),
                   (float)(g[0] * t2[0] + g[1] * t2[1] + g[2] * t2[2])};
    memcpy(&out[2], gt, sizeof gt);
}

void tr_gpu_pack_link(const transfer *t, int receiver, uint64_t k, uint32_t out[4]) {
    double t1[3], t2[3];
    tr_gpu_tangents(&t->nodes[receiver], t1, t2);
    pack_link(t, receiver, k, t1, t2, out);
}

// World names of the buffers and their buffer-texture views (--stats, debuggers).
static const char *const buf_name[TRG_COUNT] = {
    "atlas_gi.transfer_nodes",    "atlas_gi.transfer_flux",
    "atlas_gi.transfer_gathered", "atlas_gi.transfer_chunk_offsets",
    "atlas_gi.transfer_links",    "atlas_gi.transfer_texels",
    "atlas_gi.transfer_partial",  "atlas_gi.transfer_chunk_receivers"};

// Forgets the buffers and their views (the world deletes what it owns) and the leaf map.
static void untrack(tr_gpu *g) {
    if (!g->w) return;
    char name[96];
    for (int i = 0; i < TRG_COUNT; i++) {
        if (g->buf[i]) st_world_untrack(g->w, buf_name[i]);
        snprintf(name, sizeof name, "%s_tex", buf_name[i]);
        if (g->tex[i]) st_world_untrack(g->w, name);
    }
    if (g->nodes_itex) st_world_untrack(g->w, "atlas_gi.transfer_nodes_itex");
    if (g->leaf_tex) st_world_declare_target(g->w, "atlas_gi.leaf", NULL, &(st_err){0});
}

void tr_gpu_release(tr_gpu *g) {
    untrack(g);
    g->bytes = 0;
    memset(g->mem, 0, sizeof g->mem);
    memset(g->tex, 0, sizeof g->tex);
    memset(g->buf, 0, sizeof g->buf);
    g->nodes_itex = 0;
    g->leaf_tex = 0; // the world's target, forgotten above
    g->num_nodes = g->num_chunks = 0;
}

// Buffer i, world-owned, and its size counted in the --stats group `mem`.
static GLuint buffer(tr_gpu *g, int i, size_t bytes, const void *data, long long *mem,
                     st_err *err) {
    if (!bytes) bytes = 16; // GL wants a non-empty store
    *mem += (long long)bytes;
    return g->buf[i] = st_world_buffer(g->w, buf_name[i], bytes, data, err);
}

// The push walks from a texel's leaf up to the root; nodes without links
// add nothing, so the walk visits only those with links: per node its
// nearest proper ancestor with links (nodes are breadth first, parents
// before children), per texel the first node with links on its chain
// (-1: a gutter, -2: a surface texel that no link reaches).
static void linked_ancestors(const transfer *t, int32_t *up, int32_t *first) {
    for (int i = 0; i < t->num_nodes; i++) {
        int p = t->nodes[i].parent;
        up[i] = p < 0 ? -1 : t->link_off[p + 1] > t->link_off[p] ? p : up[p];
    }
    for (size_t j = 0; j < (size_t)t->W * t->H; j++) {
        int l = t->texel_leaf[j];
        first[j] = l < 0 ? -1 : t->link_off[l + 1] > t->link_off[l] ? l : up[l] >= 0 ? up[l] : -2;
    }
}

// Per node its 16 floats (centroid, area; child, slots, linked ancestor;
// tangents) and first chunk; per chunk its receiver.
static void pack_nodes(const transfer *t, const int32_t *up, float *nodes, uint32_t *choff,
                       uint32_t *recv) {
    int nn = t->num_nodes;
    uint64_t c = 0;
    for (int i = 0; i < nn; i++) {
        const tr_node *n = &t->nodes[i];
        float *o = nodes + 16 * (size_t)i;
        memcpy(o, n->c, 3 * sizeof(float));
        o[3] = n->area;
        int32_t info[4] = {n->child, (int32_t)n->begin, (int32_t)n->end, up[i]};
        memcpy(o + 4, info, sizeof info);
        double t1[3], t2[3];
        tr_gpu_tangents(n, t1, t2);
        for (int j = 0; j < 3; j++)
            o[8 + j] = (float)t1[j], o[12 + j] = (float)t2[j];
        choff[i] = (uint32_t)c;
        uint32_t b = t->link_off[i], e = t->link_off[i + 1];
        for (uint32_t q = 0; q < (e - b + TRG_CHUNK - 1) / TRG_CHUNK; q++)
            recv[c++] = (uint32_t)i;
    }
    choff[nn] = (uint32_t)c;
}

// The link records: link j of chunk c at j nch + c (nch chunks), so the link
// pass' lanes, one chunk each, read neighbouring records at every step of
// their loop (one or two cache lines per vector gather instead of one per
// lane). Packed and uploaded one row j at a time: the whole packed copy
// never sits in memory beside the GPU's (on llvmpipe both are host memory).
static bool upload_links(const tr_gpu *g, const transfer *t, const uint32_t *choff, uint64_t nch,
                         st_err *err) {
    uint32_t *row = malloc((size_t)(nch ? nch : 1) * 4 * sizeof *row);
    double *tan = malloc((size_t)(t->num_nodes ? t->num_nodes : 1) * 6 * sizeof *tan);
    if (!row || !tan) {
        free(row), free(tan);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for the transfer's GPU copy");
    }
    for (int i = 0; i < t->num_nodes; i++)
        tr_gpu_tangents(&t->nodes[i], tan + 6 * (size_t)i, tan + 6 * (size_t)i + 3);
    for (uint64_t j = 0; j < TRG_CHUNK && nch; j++) {
        memset(row, 0, (size_t)nch * 4 * sizeof *row); // padding: weight-0 links
        for (int i = 0; i < t->num_nodes; i++) {
            uint32_t c = choff[i];
            for (uint64_t k = t->link_off[i] + j; k < t->link_off[i + 1]; k += TRG_CHUNK, c++)
                pack_link(t, i, k, tan + 6 * (size_t)i, tan + 6 * (size_t)i + 3,
                          row + 4 * (size_t)c);
        }
        glNamedBufferSubData(g->buf[TRG_LINKS], (GLintptr)(j * nch * 4 * sizeof *row),
                             (GLsizeiptr)(nch * 4 * sizeof *row), row);
    }
    free(row);
    free(tan);
    return true;
}

// The buffers and their buffer-texture views.
static bool create_buffers(tr_gpu *g, const transfer *t, const float *nodes, const uint32_t *choff,
                           const uint32_t *recv, uint64_t nch, st_err *err) {
    int nn = t->num_nodes;
    uint64_t nslots = nch * TRG_CHUNK;
    uint32_t nperm = nn ? t->nodes[0].end : 0;
    long long *m = g->mem;
    if (!buffer(g, TRG_NODES, (size_t)nn * 16 * sizeof(float), nodes, &m[TRG_MEM_NODES], err) ||
        !buffer(g, TRG_FLUX, (size_t)nn * 4 * sizeof(float), NULL, &m[TRG_MEM_NODES], err) ||
        !buffer(g, TRG_GATHER, (size_t)nn * 16 * sizeof(float), NULL, &m[TRG_MEM_GATHERED], err) ||
        !buffer(g, TRG_CHOFF, ((size_t)nn + 1) * sizeof(uint32_t), choff, &m[TRG_MEM_LINKS], err) ||
        !buffer(g, TRG_LINKS, nslots * 4 * sizeof(uint32_t), NULL, &m[TRG_MEM_LINKS], err) ||
        !upload_links(g, t, choff, nch, err) ||
        !buffer(g, TRG_CHRECV, nch * sizeof(uint32_t), recv, &m[TRG_MEM_LINKS], err) ||
        !buffer(g, TRG_PERM, nperm * sizeof(uint32_t), t->perm, &m[TRG_MEM_PERM], err) ||
        !buffer(g, TRG_PARTIAL, nch * 12 * sizeof(float), NULL, &m[TRG_MEM_GATHERED], err))
        return false;
    static const GLenum fmt[TRG_COUNT] = {GL_RGBA32F,  GL_RGBA32F, GL_RGBA32F, GL_R32UI,
                                          GL_RGBA32UI, GL_R32UI,   GL_RGBA32F, GL_R32UI};
    char name[96];
    for (int i = 0; i < TRG_COUNT; i++) {
        snprintf(name, sizeof name, "%s_tex", buf_name[i]);
        if (!(g->tex[i] = st_world_buffer_texture(g->w, name, g->buf[i], fmt[i], err)))
            return false;
    }
    g->nodes_itex = st_world_buffer_texture(g->w, "atlas_gi.transfer_nodes_itex", g->buf[TRG_NODES],
                                            GL_RGBA32I, err);
    return g->nodes_itex != 0;
}

bool tr_gpu_upload(tr_gpu *g, const transfer *t, st_err *err) {
    tr_gpu_release(g);
    int nn = t->num_nodes;
    // Chunks: each receiver's links in pieces of exactly TRG_CHUNK, the last
    // one padded with links of weight 0, and whole workgroups of chunks: the
    // link shader runs no divergent loop and no early return.
    uint64_t nch = 0;
    for (int i = 0; i < nn; i++)
        nch += (t->link_off[i + 1] - t->link_off[i] + TRG_CHUNK - 1) / TRG_CHUNK;
    nch = (nch + 63) / 64 * 64;
    uint64_t nslots = nch * TRG_CHUNK;
    GLint max_tbo = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_tbo);
    if (nch * 4 > (uint64_t)max_tbo || nslots > (uint64_t)max_tbo ||
        (uint64_t)nn * 4 > (uint64_t)max_tbo || nn >= (1 << 24))
        return st_fail(err, ST_ERR_RUNTIME,
                       "atlas_gi: %llu links in %d nodes exceed the GPU's texture buffer limit (%d "
                       "texels); use a smaller transfer_leaves or a larger transfer_eps",
                       (unsigned long long)t->num_links, nn, max_tbo);
    int32_t *up = malloc((size_t)(nn ? nn : 1) * sizeof *up);
    int32_t *first = malloc((size_t)t->W * t->H * sizeof *first);
    if (up && first) linked_ancestors(t, up, first);
    float *nodes = calloc((size_t)(nn ? nn : 1) * 16, sizeof *nodes);
    uint32_t *choff = malloc(((size_t)nn + 1) * sizeof *choff);
    uint32_t *recv = calloc((size_t)(nch ? nch : 1), sizeof *recv);
    if (!up || !first || !nodes || !choff || !recv) {
        free(up), free(first), free(nodes), free(choff), free(recv);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for the transfer's GPU copy");
    }
    pack_nodes(t, up, nodes, choff, recv);
    bool ok = create_buffers(g, t, nodes, choff, recv, nch, err);
    free(nodes), free(choff), free(recv);
    const st_target_desc leaf = {GL_R32I, .width = t->W, .height = t->H, .filter = GL_NEAREST};
    const st_target *lt = ok ? st_world_alloc_target(g->w, "atlas_gi.leaf", &leaf, err) : NULL;
    if (lt) {
        g->leaf_tex = lt->color[0];
        glTextureSubImage2D(g->leaf_tex, 0, 0, 0, t->W, t->H, GL_RED_INTEGER, GL_INT, first);
    }
    free(up);
    free(first);
    g->mem[TRG_MEM_LEAF] = (long long)t->W * t->H * 4;
    for (int i = 0; i < TRG_MEM_COUNT; i++)
        g->bytes += g->mem[i];
    if (!lt) return false;
    g->num_nodes = nn;
    g->num_chunks = (int)nch;
    return st_gl_check("atlas_gi transfer upload", err);
}

// The written buffers as storage buffers, every buffer as a buffer texture
// (a shader's unused names are skipped).
static void bind(const tr_gpu *g, st_shader *sh) {
    static const int writes[3] = {TRG_FLUX, TRG_GATHER, TRG_PARTIAL};
    for (int i = 0; i < 3; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)writes[i], g->buf[writes[i]]);
    static const char *const names[TRG_COUNT] = {
        "ag_nodes_tex", "ag_flux_tex", "ag_gathered_tex", "ag_chunk_off_tex",
        "ag_links_tex", "ag_perm_tex", "ag_partial_tex",  "ag_chunk_recv_tex"};
    for (int i = 0; i < TRG_COUNT; i++)
        st_shader_texture(sh, names[i], GL_TEXTURE_BUFFER, g->tex[i]);
    st_shader_texture(sh, "ag_nodes_itex", GL_TEXTURE_BUFFER, g->nodes_itex);
}

// Storage-buffer writes become visible to the next pass' buffer-texture reads.
static void barrier(void) {
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

static GLuint groups(int n) {
    return (GLuint)((n + 63) / 64);
}

void tr_gpu_reduce(tr_gpu *g, st_shader *r, const transfer *t, GLuint l0, GLuint prev,
                   bool use_prev, GLuint area) {
    st_shader_use(r);
    bind(g, r);
    st_shader_texture(r, "ag_l0", GL_TEXTURE_2D, l0);
    st_shader_texture(r, "ag_prev", GL_TEXTURE_2D, prev);
    st_shader_set_int(r, "ag_use_prev", use_prev);
    st_shader_texture(r, "ag_area", GL_TEXTURE_2D, area);
    for (int l = t->num_levels - 1; l >= 0; l--) {
        int lb = t->level_begin[l], le = t->level_begin[l + 1];
        st_shader_set_int(r, "ag_begin", lb);
        st_shader_set_int(r, "ag_end", le);
        glDispatchCompute(groups(le - lb), 1, 1);
        barrier();
    }
}

void tr_gpu_links(tr_gpu *g, st_shader *links, st_shader *sum) {
    bind(g, links); // after the world's uniforms: they may bind textures too
    st_shader_set_int(links, "ag_num_chunks", g->num_chunks);
    glDispatchCompute((GLuint)(g->num_chunks / 64), 1, 1); // a multiple of 64
    barrier();
    st_shader_use(sum);
    bind(g, sum);
    st_shader_set_int(sum, "ag_num_nodes", g->num_nodes);
    glDispatchCompute(groups(g->num_nodes), 1, 1);
    barrier();
}

void tr_gpu_push(tr_gpu *g, st_shader *p, GLuint albedo, GLuint pos) {
    st_shader_use(p);
    bind(g, p);
    st_shader_texture(p, "ag_leaf", GL_TEXTURE_2D, g->leaf_tex);
    st_shader_texture(p, "ag_albedo", GL_TEXTURE_2D, albedo);
    st_shader_texture(p, "ag_pos", GL_TEXTURE_2D, pos);
    st_draw_fullscreen();
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
}
