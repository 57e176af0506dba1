// The precomputed transfer's buffers (modules/atlas_gi/transfer.h): cluster
// nodes in breadth-first order, per node the flux of its senders and its
// gathered radiance, links grouped by receiver node.
#ifndef AG_TRANSFER_GLSL
#define AG_TRANSFER_GLSL
struct ag_node {
    vec4 ca;    // area-weighted centroid, area
    vec4 nc;    // mean normal, cos of the normal cone's half-angle
    ivec4 info; // first child (-1: leaf), first and end texel slot, parent (-1: root)
};
layout(std430, binding = 0) readonly buffer ag_tr_nodes { ag_node ag_nodes[]; };
layout(std430, binding = 1) buffer ag_tr_flux { vec4 ag_flux[]; };
// Per node: the gathered radiance at its centroid and its derivatives along
// x, y, z (4 vec4s), so texels off the centroid get a first-order correction.
layout(std430, binding = 2) buffer ag_tr_gathered { vec4 ag_gathered[]; };
layout(std430, binding = 3) readonly buffer ag_tr_off { uint ag_link_off[]; };
layout(std430, binding = 4) readonly buffer ag_tr_links { uvec2 ag_links[]; }; // sender node, weight bits
layout(std430, binding = 5) readonly buffer ag_tr_perm { uint ag_perm[]; };    // per slot: texel y W + x
#endif
