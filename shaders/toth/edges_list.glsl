// toth's edges pass: the list of full-resolution pixels that march their own
// ray, appended by the select step (edges.frag) and read by the march step
// (edges_march.comp). toth.c clears the count before the select step.
// Bindings 4 and 5 (common/bvh.glsl holds 6 and 7).
#ifndef TOTH_EDGES_LIST_GLSL
#define TOTH_EDGES_LIST_GLSL
layout(std430, binding = 4) buffer toth_edges_buf {
    uint toth_edges_count;  // pixels listed
    uint toth_edges_list[]; // x | y << 16
};

// The march step's work group: TOTH_EDGES_GROUP consecutive entries. The
// select step counts the groups (x of an indirect dispatch; toth.c sets
// y = z = 1), so nothing is read back: llvmpipe spreads groups evenly over
// its threads, where a draw would hand out 64 x 64 pixel tiles.
#define TOTH_EDGES_GROUP 64
#ifdef TOTH_EDGES_SELECT
layout(std430, binding = 5) buffer toth_edges_dispatch_buf { uint toth_edges_groups[3]; };

void toth_edges_append(ivec2 p) {
    uint i = atomicAdd(toth_edges_count, 1u);
    toth_edges_list[i] = uint(p.x) | (uint(p.y) << 16);
    if (i % uint(TOTH_EDGES_GROUP) == 0u) atomicAdd(toth_edges_groups[0], 1u);
}
#endif
#endif
