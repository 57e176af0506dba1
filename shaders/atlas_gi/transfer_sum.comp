// Precomputed transfer, step 3 of a relight: per node the sum of its chunks'
// partial sums, the tangent derivatives turned into x, y, z ones, stored
// with the node's centroid and nearest linked ancestor for the push.
#include "atlas_gi/transfer.glsl"
layout(local_size_x = 64) in;
uniform int ag_num_nodes;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= ag_num_nodes) return;
    vec3 v = vec3(0.0), g1 = vec3(0.0), g2 = vec3(0.0);
    int e = int(texelFetch(ag_chunk_off_tex, i + 1).r);
    for (int c = int(texelFetch(ag_chunk_off_tex, i).r); c < e; c++) {
        v += texelFetch(ag_partial_tex, 3 * c).rgb;
        g1 += texelFetch(ag_partial_tex, 3 * c + 1).rgb;
        g2 += texelFetch(ag_partial_tex, 3 * c + 2).rgb;
    }
    vec3 ca = texelFetch(ag_nodes_tex, 4 * i).xyz;
    float up = float(texelFetch(ag_nodes_itex, 4 * i + 1).w); // exact below 2^24
    vec3 t1 = texelFetch(ag_nodes_tex, 4 * i + 2).xyz, t2 = texelFetch(ag_nodes_tex, 4 * i + 3).xyz;
    int o = 4 * i;
    ag_gathered[o] = vec4(v, ca.x);
    ag_gathered[o + 1] = vec4(g1 * t1.x + g2 * t2.x, ca.y);
    ag_gathered[o + 2] = vec4(g1 * t1.y + g2 * t2.y, ca.z);
    ag_gathered[o + 3] = vec4(g1 * t1.z + g2 * t2.z, up);
}
