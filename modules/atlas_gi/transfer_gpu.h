// atlas_gi: the precomputed transfer (transfer.h) on the GPU, and a relight
// as GPU passes over it, with no read-back.
//
// Layout, chosen for llvmpipe (which runs 8 invocations per AVX2 vector and
// one workgroup per thread):
//   - links, 16 bytes each, grouped by receiver: sender node, w / A_sender
//     (so the sender's flux needs no division by its area) and the link's
//     gradient factor grad ln(cos_x cos_j / d^2) in the receiver's plane, as
//     two floats along the receiver node's tangents (zero for a receiver
//     that is not flat). Everything about a link that does not depend on
//     the light is computed once here, not per relight (the medium's
//     segment length comes from the nodes, in a shader variant: llvmpipe
//     runs both sides of a branch inside a loop).
//   - chunks of exactly TRG_CHUNK links of one receiver (padded with
//     weight-0 links), one invocation per chunk: every invocation runs the
//     same loop, so llvmpipe needs no per-lane masks in it (per receiver
//     node the counts range from 1 to thousands); partial sums per chunk,
//     then one invocation per node adds its chunks. Link j of chunk c is
//     stored at j num_chunks + c, so the 8 lanes of a vector read 8
//     neighbouring records at each step of the loop.
//   - the passes read through buffer textures and write through storage
//     buffers: llvmpipe turns a texel fetch into one vector gather, but a
//     storage-buffer load into a loop with a bounds-check branch per lane.
//   - per node: centroid and area, child, slots and the nearest ancestor
//     that has links (the push skips nodes that add nothing), and the two
//     tangents (4 texels); the sum pass turns the tangent derivatives back
//     into x, y, z ones.
//   - per node, what the push to the texels needs in 4 vec4s: the gathered
//     radiance and its x, y, z derivatives, with the centroid and that
//     ancestor in the w components (one contiguous 64-byte read per node).
#ifndef ATLAS_GI_TRANSFER_GPU_H
#define ATLAS_GI_TRANSFER_GPU_H
#include "st_gl.h"
#include "st_shader.h"
#include "st_world_api.h"
#include "transfer.h"

#define TRG_CHUNK 32 // links per chunk

enum {
    TRG_NODES,   // per node: centroid, area; child, first and end slot, linked ancestor; t1; t2
    TRG_FLUX,    // per node: sum a_j L_j of its texels
    TRG_GATHER,  // per node: 4 vec4 (above)
    TRG_CHOFF,   // per node: its first chunk (num_nodes + 1)
    TRG_LINKS,   // per link: uvec4 (above)
    TRG_PERM,    // per texel slot: atlas texel y W + x
    TRG_PARTIAL, // per chunk: 3 vec4 partial sums (value, d/dt1, d/dt2)
    TRG_CHRECV,  // per chunk: its receiver node (the medium)
    TRG_COUNT
};

// Bytes per group, for --stats.
enum { TRG_MEM_NODES, TRG_MEM_LINKS, TRG_MEM_GATHERED, TRG_MEM_PERM, TRG_MEM_LEAF, TRG_MEM_COUNT };

// The stringized chunk size, for the programs' defines ("AG_CHUNK " TRG_CHUNK_S).
#define TRG_STR_(x) #x
#define TRG_STR(x) TRG_STR_(x)
#define TRG_CHUNK_S TRG_STR(TRG_CHUNK)

typedef struct tr_gpu {
    st_world *w; // owns the buffers, their buffer textures and the leaf map (a declared target)
    GLuint buf[TRG_COUNT];
    GLuint tex[TRG_COUNT], nodes_itex; // buffer-texture views: the passes read through them
    GLuint leaf_tex; // R32I: per texel the first node with links up from its leaf (-1 gutter)
    int num_nodes, num_chunks;
    long long mem[TRG_MEM_COUNT], bytes; // for the --stats line (the world's table counts them too)
} tr_gpu;

// A node's tangents t1, t2 (unit, orthogonal to its mean normal and each
// other; arbitrary for a node without one).
void tr_gpu_tangents(const tr_node *n, double t1[3], double t2[3]);
// The largest receiver radius, relative to the sender's height above the
// receiver's plane (rad / (n . d)), at which a link keeps its gradient: past
// it (a crease, a contact) the kernel is far from linear over the node (issue 34).
#define TR_GPU_GRAD_MAX 0.35
// One link as uploaded: the four words above.
void tr_gpu_pack_link(const transfer *t, int receiver, uint64_t k, uint32_t out[4]);

// Uploads t into world-owned buffers (replacing what was there); W x H is the atlas.
bool tr_gpu_upload(tr_gpu *g, const transfer *t, st_err *err);
// Hands the buffers back to the world (which deletes them).
void tr_gpu_release(tr_gpu *g);

// A relight's steps for one bounce, each with its program (the plugin's
// declared "transfer_reduce.comp", ...); they bind their buffers themselves.
// Flux per node from L0 (+ prev when use_prev) times the texel areas.
void tr_gpu_reduce(tr_gpu *g, st_shader *reduce, const transfer *t, GLuint l0, GLuint prev,
                   bool use_prev, GLuint area);
// The links' sums per node with `links` (bound by the caller with the
// world's uniforms: the medium variant attenuates along each link), then
// the per-node sum with `sum`.
void tr_gpu_links(tr_gpu *g, st_shader *links, st_shader *sum);
// Per texel rho/pi times the sum over its leaf and ancestors, into the bound
// framebuffer (attachment 0: this bounce; 1: the accumulation).
void tr_gpu_push(tr_gpu *g, st_shader *push, GLuint albedo, GLuint pos);
#endif
