// The precomputed transfer's buffers (modules/atlas_gi/transfer_gpu.h):
// cluster nodes in breadth-first order, per node the flux of its texels and
// its gathered radiance, links grouped by receiver node in chunks.
// Reads go through buffer textures, writes through storage buffers: on
// llvmpipe a texel fetch is one vector gather, a storage-buffer load a loop
// with a branch per lane.
#ifndef AG_TRANSFER_GLSL
#define AG_TRANSFER_GLSL
// Per node 4 texels: area-weighted centroid, area; first child (-1: leaf),
// first and end texel slot, nearest ancestor with links (-1: none); tangents
// t1, t2 of its mean
// plane. One buffer, two views.
uniform samplerBuffer ag_nodes_tex;
uniform isamplerBuffer ag_nodes_itex;
uniform samplerBuffer ag_flux_tex;      // per node: sum a_j L_j of its texels
// Per node 4 texels: the gathered radiance at the centroid and its
// derivatives along x, y, z (rgb), so texels off the centroid get a
// first-order correction; in a the centroid's x, y, z and the nearest
// ancestor with links (a float).
uniform samplerBuffer ag_gathered_tex;
uniform usamplerBuffer ag_chunk_off_tex; // per node: its first chunk (num_nodes + 1)
// Per link (link j of chunk c at j num_chunks + c): sender node,
// w / A_sender (float bits), the gradient factor along the receiver's t1, t2
// (floats).
uniform usamplerBuffer ag_links_tex;
uniform usamplerBuffer ag_chunk_recv_tex; // per chunk: its receiver node
uniform usamplerBuffer ag_perm_tex;     // per texel slot: atlas texel y W + x
uniform samplerBuffer ag_partial_tex;   // per chunk 3 texels: value, d/dt1, d/dt2
layout(std430, binding = 1) writeonly buffer ag_tr_flux { vec4 ag_flux[]; };
layout(std430, binding = 2) writeonly buffer ag_tr_gathered { vec4 ag_gathered[]; };
layout(std430, binding = 6) writeonly buffer ag_tr_partial { vec4 ag_partial[]; };
#endif
