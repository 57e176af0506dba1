// Precomputed transfer, step 3 of a relight: per node the sum of its chunks'
// partial sums, stored with the node's centroid and parent for the push.
#include "atlas_gi/transfer.glsl"
layout(local_size_x = 64) in;
uniform int ag_num_nodes;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= ag_num_nodes) return;
    vec3 v = vec3(0.0), gx = vec3(0.0), gy = vec3(0.0), gz = vec3(0.0);
    int e = int(texelFetch(ag_chunk_off_tex, i + 1).r);
    for (int c = int(texelFetch(ag_chunk_off_tex, i).r); c < e; c++) {
        v += texelFetch(ag_partial_tex, 4 * c).rgb;
        gx += texelFetch(ag_partial_tex, 4 * c + 1).rgb;
        gy += texelFetch(ag_partial_tex, 4 * c + 2).rgb;
        gz += texelFetch(ag_partial_tex, 4 * c + 3).rgb;
    }
    vec3 ca = texelFetch(ag_nodes_tex, 2 * i).xyz;
    float parent = float(texelFetch(ag_nodes_itex, 2 * i + 1).w); // exact below 2^24
    int o = 4 * i;
    ag_gathered[o] = vec4(v, ca.x);
    ag_gathered[o + 1] = vec4(gx, ca.y);
    ag_gathered[o + 2] = vec4(gy, ca.z);
    ag_gathered[o + 3] = vec4(gz, parent);
}
