// toth's edges pass: the list of full-resolution pixels that march their own
// ray, appended by the select step (edges.frag) and read by the march step
// (edges_march.vert/.frag). toth.c clears the count before the select step.
// Binding 4 (common/bvh.glsl holds 6 and 7).
#ifndef TOTH_EDGES_LIST_GLSL
#define TOTH_EDGES_LIST_GLSL
layout(std430, binding = 4) buffer toth_edges_buf {
    uint toth_edges_count;  // pixels listed
    uint toth_edges_list[]; // x | y << 16
};

// The march step's grid: list entry i at fragment c of a grid of
// toth_edges_width columns, 16 consecutive entries to each 4 x 4 block (one
// llvmpipe block, two 8-wide vectors), so the lanes of a block march
// neighbouring pixels the select step listed together.
uniform int toth_edges_width; // a multiple of 4
int toth_edges_index(ivec2 c) {
    return ((c.y >> 2) * (toth_edges_width >> 2) + (c.x >> 2)) * 16 + (c.y & 3) * 4 + (c.x & 3);
}
#endif
