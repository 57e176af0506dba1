// The transfer's GPU link records (transfer_gpu.c), checked on the CPU
// against independent numbers:
//   - a node's tangents are orthonormal and orthogonal to its normal, for
//     normals along and between the axes;
//   - a packed link holds the sender, w / A_sender, and the gradient of
//     ln(cos_x cos_j / d^2) with respect to the receiver point along the
//     receiver's plane, compared with central finite differences of that
//     kernel; a curved receiver (wide normal cone) gets no gradient, nor
//     does a link whose gradient times the receiver's radius exceeds
//     TR_GPU_GRAD_MAX (issue 34: the term overshot at creases).
#include "st_test.h"
#include "transfer_gpu.h"

static void node(tr_node *n, double cx, double cy, double cz, double nx, double ny, double nz,
                 float cone, float area) {
    memset(n, 0, sizeof *n);
    double l = sqrt(nx * nx + ny * ny + nz * nz);
    n->c[0] = (float)cx, n->c[1] = (float)cy, n->c[2] = (float)cz;
    n->n[0] = (float)(nx / l), n->n[1] = (float)(ny / l), n->n[2] = (float)(nz / l);
    n->cone = cone;
    n->area = area;
    n->child = n->parent = -1;
}

static double dot(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// ln(cos_x cos_j / d^2) for receiver point x (normal nr), sender point y
// (normal ns), both normals as floats.
static double ln_kernel(const double *x, const float *nr, const float *y, const float *ns) {
    double d[3] = {y[0] - x[0], y[1] - x[1], y[2] - x[2]};
    double cr = nr[0] * d[0] + nr[1] * d[1] + nr[2] * d[2];
    double cs = -(ns[0] * d[0] + ns[1] * d[1] + ns[2] * d[2]);
    return log(cr) + log(cs) - 2 * log(dot(d, d));
}

static void tangents(void) {
    const double ns[6][3] = {{0, 1, 0}, {1, 0, 0},        {0, 0, -1},
                             {1, 1, 1}, {-0.3, 0.2, 0.9}, {0.59, -0.8, 0.1}};
    for (int i = 0; i < 6; i++) {
        tr_node n;
        node(&n, 0, 0, 0, ns[i][0], ns[i][1], ns[i][2], 0, 1);
        double t1[3], t2[3], z[3] = {n.n[0], n.n[1], n.n[2]};
        tr_gpu_tangents(&n, t1, t2);
        CHECK_REL(dot(t1, t1), 1.0, 1e-9, 0);
        CHECK_REL(dot(t2, t2), 1.0, 1e-9, 0);
        CHECK(fabs(dot(t1, t2)) < 1e-9, "t1.t2 = %g", dot(t1, t2));
        CHECK(fabs(dot(t1, z)) < 1e-6 && fabs(dot(t2, z)) < 1e-6, "normal %d: t.n = %g, %g", i,
              dot(t1, z), dot(t2, z));
    }
}

static void links(void) {
    // Receiver: a flat patch tilted off the axes; senders above it, one a
    // curved node (its cosine term is left out, as documented).
    tr_node nodes[4];
    node(&nodes[0], 0.1, 0.2, -0.1, 0.1, 1, 0.2, 0.05f, 0.04f);
    node(&nodes[1], 0.7, 1.1, 0.3, -0.2, -1, 0.1, 0.02f, 0.02f);
    node(&nodes[2], -0.5, 0.8, 0.6, 0.4, -0.6, -0.5, 0.1f, 0.5f);
    node(&nodes[3], 0.1, 0.2, -0.1, 0, 1, 0, 1.2f, 0.04f); // curved receiver
    uint32_t link_node[3] = {1, 2, 1};
    float link_w[3] = {0.013f, 0.25f, 0.013f};
    transfer t = {.num_nodes = 4, .nodes = nodes, .link_node = link_node, .link_w = link_w};
    double t1[3], t2[3];
    tr_gpu_tangents(&nodes[0], t1, t2);
    for (int k = 0; k < 2; k++) {
        uint32_t out[4];
        tr_gpu_pack_link(&t, 0, (uint64_t)k, out);
        float w, g[2];
        memcpy(&w, &out[1], 4);
        memcpy(g, &out[2], 8);
        const tr_node *s = &nodes[link_node[k]];
        CHECK(out[0] == link_node[k], "sender %u", out[0]);
        CHECK_REL(w, link_w[k] / s->area, 1e-6, 0);
        // Central differences along t1, t2 at the receiver's centroid.
        const double h = 1e-5;
        for (int a = 0; a < 2; a++) {
            const double *t_ = a ? t2 : t1;
            double xp[3], xm[3];
            for (int i = 0; i < 3; i++)
                xp[i] = nodes[0].c[i] + h * t_[i], xm[i] = nodes[0].c[i] - h * t_[i];
            double fd =
                (ln_kernel(xp, nodes[0].n, s->c, s->n) - ln_kernel(xm, nodes[0].n, s->c, s->n)) /
                (2 * h);
            printf("link %d, tangent %d: packed %.6f, finite differences %.6f\n", k, a + 1, g[a],
                   fd);
            CHECK_REL(g[a], fd, 1e-4, 1e-5);
        }
    }
    // A curved receiver: no gradient.
    uint32_t out[4];
    tr_gpu_pack_link(&t, 3, 2, out);
    float g[2];
    memcpy(g, &out[2], 8);
    CHECK(g[0] == 0 && g[1] == 0, "curved receiver: gradient %g %g", g[0], g[1]);
    // A receiver node large against the sender's height above its plane
    // (rad > TR_GPU_GRAD_MAX n . d: a crease) gets no gradient; just under
    // the bound it keeps it.
    tr_gpu_pack_link(&t, 0, 0, out);
    memcpy(g, &out[2], 8);
    double gl = hypot(g[0], g[1]); // the receiver is flat: its gradient lies in its plane
    CHECK(gl > 0, "flat receiver: gradient %g", gl);
    double cr = 0;
    for (int a = 0; a < 3; a++)
        cr += nodes[0].n[a] * (nodes[1].c[a] - nodes[0].c[a]);
    CHECK(cr > 0, "the sender lies above the receiver: n . d = %g", cr);
    float rad = nodes[0].rad;
    nodes[0].rad = (float)(1.01 * TR_GPU_GRAD_MAX * cr);
    tr_gpu_pack_link(&t, 0, 0, out);
    memcpy(g, &out[2], 8);
    CHECK(g[0] == 0 && g[1] == 0, "rad above the bound: gradient %g %g", g[0], g[1]);
    nodes[0].rad = (float)(0.99 * TR_GPU_GRAD_MAX * cr);
    tr_gpu_pack_link(&t, 0, 0, out);
    memcpy(g, &out[2], 8);
    CHECK_REL(hypot(g[0], g[1]), gl, 1e-6, 0);
    nodes[0].rad = rad;
}

int main(void) {
    tangents();
    links();
    return st_test_summary("test_atlas_gi_transfer_pack");
}
