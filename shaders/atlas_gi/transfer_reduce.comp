// Precomputed transfer, step 1 of a relight: per cluster node the flux of
// the senders, sum a_j L_j (L = L0, plus the previous bounce when
// ag_use_prev), one tree level per dispatch from the leaves up.
#include "atlas_gi/transfer.glsl"
layout(local_size_x = 64) in;
uniform int ag_begin, ag_end; // this level's nodes
uniform sampler2D ag_l0;
uniform sampler2D ag_prev;
uniform int ag_use_prev;
uniform sampler2D ag_area;

void main() {
    int i = ag_begin + int(gl_GlobalInvocationID.x);
    if (i >= ag_end) return;
    ivec4 info = texelFetch(ag_nodes_itex, 4 * i + 1);
    vec3 f;
    if (info.x < 0) {
        int w = textureSize(ag_l0, 0).x;
        f = vec3(0.0);
        for (int k = info.y; k < info.z; k++) {
            int j = int(texelFetch(ag_perm_tex, k).r);
            ivec2 t = ivec2(j % w, j / w);
            vec3 L = texelFetch(ag_l0, t, 0).rgb;
            if (ag_use_prev != 0) L += texelFetch(ag_prev, t, 0).rgb;
            f += L * texelFetch(ag_area, t, 0).r;
        }
    } else {
        f = texelFetch(ag_flux_tex, info.x).rgb + texelFetch(ag_flux_tex, info.x + 1).rgb;
    }
    ag_flux[i] = vec4(f, 0.0);
}
