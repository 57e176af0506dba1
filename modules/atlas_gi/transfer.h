// atlas_gi: precomputed light transfer for relighting static geometry.
//
// Once per atlas, on the CPU (Embree for visibility, all cores): a binary
// cluster tree over the valid atlas texels (a k-d tree over position and
// normal; leaves are single texels, or groups of a few on large atlases)
// and hierarchical links (receiver node, sender node, weight) chosen by
// refinement that does not depend on the light: a link is kept when both
// nodes look small from each other (A/(pi d^2) below eps, a flat receiver),
// are not within a few radii of each other and the form factor varies by
// less than `spread` over the link's texel pairs; otherwise the larger node
// is opened. Near contact edges this goes down to leaves; far away whole
// walls link to whole walls. Texels buried inside closed solids borrow a
// free neighbour's position (they reach the image through the filter);
// those with none (deep inside a solid: the back side of a double-sided
// closed mesh) are left out.
//
// A link's weight is w = integral over the sender of
//   V cos+x cos+j pi / (pi d^2 + a_j) dA_j,
// averaged over the receiver: the kernel over stratified texel pairs, V
// from one Embree ray for each of a few of them.
// Each relight then needs only GPU passes: the senders' area-weighted mean
// radiance per node (a reduction up the tree), per node the sum over its
// links w L_s e^(-sigma_t d), and per texel rho/pi times the sum of its
// ancestors' gathered values. A small bright spot is counted exactly in
// its node's mean: no light-dependent sampling, no noise.
//
// No GL here: the plugin and the tests share this file.
#ifndef ATLAS_GI_TRANSFER_H
#define ATLAS_GI_TRANSFER_H
#include "st_base.h"
#include <stdint.h>

typedef struct tr_opts {
    double eps;       // largest A_s/(pi d^2) of a sender node in a link
    double recv;      // receivers: at most recv eps
    double near_k;    // nodes closer than near_k (r_r + r_s) are opened
    double cone_deg;  // receivers with a wider normal cone are opened
    int samples;      // texel pairs with a visibility ray per link between clusters
    int kernel;       // texel pairs for the kernel per link (no rays; at least samples)
    double spread;    // open links whose form factor varies more than this (0: off)
    int min_split;    // partly blocked links open nodes of more texels than this
    int threads;      // 0: all cores
    double offset;    // ray ends lie this far off the surfaces (m)
    bool visibility;  // false: no rays (tests of the geometry alone)
    double leaf_size; // a leaf of several texels spans at most this fraction of the scene (0: any)
    int max_leaves;   // texels are grouped into at most this many leaves (0: one texel each)
} tr_opts;

typedef struct tr_node {
    float c[3], area;    // area-weighted centroid, area (m^2)
    float n[3], cone;    // mean normal, half-angle of the normal cone (rad)
    float rad;           // bounding radius around c
    int32_t child;       // first child (the second is child + 1), -1 for a leaf
    int32_t parent;      // -1 for the root
    uint32_t begin, end; // texel slots in perm
} tr_node;

typedef struct transfer {
    int W, H;
    int num_nodes;
    tr_node *nodes; // breadth-first: every level is a contiguous range
    uint32_t *perm; // per slot: atlas texel index (y W + x)
    int num_levels;
    int *level_begin;    // num_levels + 1
    int32_t *texel_leaf; // per atlas texel: its leaf node, -1 for gutters
    // Links grouped by receiver node: link_off[r] .. link_off[r + 1].
    uint32_t *link_off;
    uint32_t *link_node;
    float *link_w;
    uint64_t num_links;
    // Statistics for --stats.
    double seconds;
    double cpu_seconds; // process CPU time of the build (all threads)
    uint64_t rays;
    int threads;
    int leaf_texels; // most texels per leaf
    uint32_t buried; // texels inside closed solids that borrowed a free neighbour's position
    uint32_t sealed; // buried texels with no free neighbour: left out of the transfer
} transfer;

// pos: W H x 4 floats (world position, texel area; area 0 = gutter),
// nrm: W H x 4 floats (unit normal, _). tris: num_tris x 9 floats (world
// triangles that block light).
bool transfer_build(transfer *t, int W, int H, const float *pos, const float *nrm,
                    const float *tris, uint32_t num_tris, const tr_opts *o, st_err *err);
void transfer_free(transfer *t);
// Bytes the CPU copy holds (what the GPU copy holds too, roughly).
uint64_t transfer_bytes(const transfer *t);

#endif
