// toth's edges pass, march step: one quad (a 4-vertex strip) over the rows of
// 4 x 4 blocks of the grid (toth/edges_list.glsl) that the listed pixels
// fill; drawn into a framebuffer without attachments, toth_edges_width x
// toth_edges_height.
#include "toth/edges_list.glsl"
uniform int toth_edges_height; // the grid's rows

void main() {
    int blocks = (int(toth_edges_count) + 15) / 16, per_row = toth_edges_width / 4;
    float rows = float(4 * ((blocks + per_row - 1) / per_row));
    vec2 c = vec2(gl_VertexID & 1, gl_VertexID >> 1) * vec2(1.0, rows / float(toth_edges_height));
    gl_Position = vec4(c * 2.0 - 1.0, 0.0, 1.0);
}
