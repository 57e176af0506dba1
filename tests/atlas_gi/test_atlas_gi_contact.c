// Issue 34: the transfer at a contact, where a block stands on a floor slab
// (closed meshes whose faces coincide under the block), on the CPU (no GL):
//   - every texel inside the slab (its bottom face's back side, as a
//     double-sided mesh has it) is sealed, under the block too: there a
//     buried-test ray meets the slab's top from behind and the block's
//     bottom from the front at the same distance, and a texel counted free
//     joined the floor's nodes and blocked their links;
//   - per floor texel next to the block, the light gathered from a ceiling
//     of radiance 1 through the links (sum of w times the sender's mean
//     over the texel's leaf and ancestors) against a brute-force sum over
//     every ceiling texel of a_j pi K(x, j) V(x, j) with an exact ray each.
// Before the fix the floor beside the tall block got 17-35 % of it.
#include "st_test.h"
#include "transfer.h"
#include <embree3/rtcore.h>

#define G 40                // texels per tile side
#define GAP 4               // empty atlas columns between tiles (no borrowing across)
#define W (3 * G + 2 * GAP) // tiles: floor top, slab bottom's back side, ceiling
#define HALF 1.0            // the room spans [-1, 1] in x and z
#define SLAB 0.05
#define CEIL 2.0

// A box's 12 outward (counter-clockwise) triangles, rotated by ang about y.
static int box(float *t, const double *lo, const double *hi, double ang) {
    static const int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    double v[8][3], c = cos(ang), s = sin(ang);
    for (int i = 0; i < 8; i++) {
        double p[3] = {i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]};
        v[i][0] = c * p[0] + s * p[2], v[i][1] = p[1], v[i][2] = -s * p[0] + c * p[2];
    }
    for (int k = 0; k < 6; k++) {
        const int tri[2][3] = {{f[k][0], f[k][1], f[k][2]}, {f[k][0], f[k][2], f[k][3]}};
        for (int q = 0; q < 2; q++)
            for (int j = 0; j < 3; j++)
                for (int a = 0; a < 3; a++)
                    t[(2 * k + q) * 9 + 3 * j + a] = (float)v[tri[q][j]][a];
    }
    return 12;
}

// Is p (world) inside the block's footprint, grown by m?
static bool in_block(double x, double z, double ang, double hb, double m) {
    double c = cos(ang), s = sin(ang), u = c * x - s * z, w = s * x + c * z;
    return fabs(u) < hb + m && fabs(w) < hb + m;
}

static void texel(float *pos, float *nrm, int cell, double x, double y, double z, float ny) {
    double h = 2 * HALF / G;
    pos[4 * cell] = (float)x, pos[4 * cell + 1] = (float)y, pos[4 * cell + 2] = (float)z;
    pos[4 * cell + 3] = (float)(h * h);
    nrm[4 * cell + 1] = ny;
}

static double brute(RTCScene sc, const float *pos, const float *nrm, int x, double off) {
    double sum = 0;
    for (int j = 0; j < W * G; j++) {
        if (!(pos[4 * j + 3] > 0) || nrm[4 * j + 1] > -0.5f) continue; // the ceiling only
        const float *p = pos + 4 * x, *q = pos + 4 * j;
        double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], cx = d[1] / sqrt(d2), cy = cx;
        struct RTCRay r = {.org_x = p[0],
                           .org_y = (float)(p[1] + off),
                           .org_z = p[2],
                           .dir_x = (float)d[0],
                           .dir_y = (float)(d[1] - 2 * off),
                           .dir_z = (float)d[2],
                           .tnear = 1e-4f,
                           .tfar = 1 - 1e-4f,
                           .mask = 0xFFFFFFFFu};
        struct RTCIntersectContext ic;
        rtcInitIntersectContext(&ic);
        rtcOccluded1(sc, &ic, &r);
        if (r.tfar >= 0) sum += q[3] * cx * cy / (M_PI * d2 + q[3]) * M_PI;
    }
    return sum;
}

// The same triangles in a scene of our own for the exact rays.
static RTCScene exact_scene(RTCDevice dev, const float *tris, int n) {
    RTCScene sc = rtcNewScene(dev);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), 3 * (size_t)n);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), (size_t)n);
    memcpy(vb, tris, 9 * sizeof(float) * (size_t)n);
    for (int i = 0; i < 3 * n; i++)
        ib[i] = (unsigned)i;
    rtcCommitGeometry(g);
    rtcAttachGeometry(sc, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(sc);
    return sc;
}

int main(void) {
    const double ang = 0.5236, hb = 0.3, h = 2 * HALF / G; // the block: 0.6 m wide, turned 30 deg
    float tris[36 * 9];
    int n = box(tris, (double[]){-HALF, -SLAB, -HALF}, (double[]){HALF, 0, HALF}, 0);
    n += box(tris + 9 * n, (double[]){-HALF, CEIL, -HALF}, (double[]){HALF, CEIL + SLAB, HALF}, 0);
    // The block's bottom a rounding error below the floor's top, as an
    // exported transform puts it (ds_cornell's tall block: 0.6 - 0.5 x 1.2).
    n += box(tris + 9 * n, (double[]){-hb, -1e-7, -hb}, (double[]){hb, 1.2, hb}, ang);
    float *pos = calloc(4 * W * G, sizeof *pos), *nrm = calloc(4 * W * G, sizeof *nrm);
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            double x = -HALF + (i + 0.5) * h, z = -HALF + (j + 0.5) * h;
            texel(pos, nrm, j * W + i, x, 0, z, 1);                     // floor top
            texel(pos, nrm, j * W + G + GAP + i, x, -SLAB, z, 1);       // inside the slab
            texel(pos, nrm, j * W + 2 * (G + GAP) + i, x, CEIL, z, -1); // ceiling
        }
    tr_opts o = {.eps = 0.15,
                 .recv = 0.25,
                 .near_k = 2.0,
                 .cone_deg = 20.0,
                 .samples = 4,
                 .kernel = 16,
                 .spread = 0.15 / 50,
                 .min_split = 4,
                 .leaf_size = 0.05,
                 .offset = 1e-4 * 2.1,
                 .visibility = true,
                 .max_leaves = 8192};
    transfer t;
    st_err err = {0};
    CHECK(transfer_build(&t, W, G, pos, nrm, tris, (uint32_t)n, &o, &err), "%s", err.msg);
    int free_inside = 0;
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++)
            free_inside += t.texel_leaf[j * W + G + GAP + i] >= 0;
    printf("texels inside the slab in the transfer: %d of %d (buried %u, sealed %u)\n", free_inside,
           G * G, t.buried, t.sealed);
    CHECK(free_inside == 0, "%d texels inside the floor slab take part", free_inside);
    // Each node's mean radiance with the ceiling at 1, everything else 0.
    double *mean = calloc((size_t)t.num_nodes, sizeof *mean);
    for (int k = 0; k < t.num_nodes; k++) {
        double a = 0, f = 0;
        for (uint32_t s = t.nodes[k].begin; s < t.nodes[k].end; s++) {
            uint32_t id = t.perm[s];
            a += pos[4 * id + 3], f += nrm[4 * id + 1] < -0.5f ? pos[4 * id + 3] : 0;
        }
        mean[k] = a > 0 ? f / a : 0;
    }
    RTCDevice dev = rtcNewDevice("threads=1");
    RTCScene sc = exact_scene(dev, tris, n);
    double lo = INFINITY, hi = 0;
    int count = 0;
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            int x = j * W + i;
            double px = pos[4 * x], pz = pos[4 * x + 2];
            if (!in_block(px, pz, ang, hb, 0.2) || in_block(px, pz, ang, hb, h)) continue;
            double tr = 0;
            for (int k = t.texel_leaf[x]; k >= 0; k = t.nodes[k].parent)
                for (uint32_t l = t.link_off[k]; l < t.link_off[k + 1]; l++)
                    tr += t.link_w[l] * mean[t.link_node[l]];
            double r = tr / brute(sc, pos, nrm, x, o.offset);
            lo = fmin(lo, r), hi = fmax(hi, r), count++;
        }
    printf("floor texels within 0.2 m of the block: %d, transfer / exact from the ceiling: "
           "%.3f .. %.3f\n",
           count, lo, hi);
    // 4 rays per link leave +-30 % over single texels (README, known limits).
    CHECK(count > 50 && lo >= 0.6 && hi <= 1.5, "transfer / exact %.3f .. %.3f", lo, hi);
    rtcReleaseScene(sc);
    rtcReleaseDevice(dev);
    transfer_free(&t);
    free(mean);
    free(pos);
    free(nrm);
    return st_test_summary("test_atlas_gi_contact");
}
