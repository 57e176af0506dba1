// Precomputed transfer, step 4: per atlas texel rho/pi times the sum of the
// gathered values of its leaf and every ancestor that has links (a node's
// links stand for all texels under it), each corrected to first order for
// the texel's offset from the node's centroid. Outputs as the gather's: this
// bounce, and the running sum the resolve pass divides by the frame count
// (here 1).
#include "atlas_gi/transfer.glsl"
#include "common/estimator.glsl"
// Per texel the first node with links on the way up from its leaf (-1 in
// gutters, -2 where no link reaches); each node names the next such one.
uniform isampler2D ag_leaf;
uniform sampler2D ag_albedo;
uniform sampler2D ag_pos;
layout(location = 0) out vec4 o_bounce;
layout(location = 1) out vec4 o_accum;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int n = texelFetch(ag_leaf, t, 0).r;
    if (n == -1) {
        o_bounce = vec4(0.0);
        o_accum = vec4(0.0);
        return;
    }
    vec3 x = texelFetch(ag_pos, t, 0).xyz;
    vec3 sum = vec3(0.0);
    for (int guard = 0; n >= 0 && guard < 64; guard++) {
        // First order about the node's centroid, kept within [0, 2] x the
        // centroid's value so a steep kernel cannot go negative.
        vec4 a = texelFetch(ag_gathered_tex, 4 * n), dx = texelFetch(ag_gathered_tex, 4 * n + 1),
             dy = texelFetch(ag_gathered_tex, 4 * n + 2), dz = texelFetch(ag_gathered_tex, 4 * n + 3);
        vec3 q = x - vec3(a.w, dx.w, dy.w);
        vec3 lin = a.rgb + dx.rgb * q.x + dy.rgb * q.y + dz.rgb * q.z;
        sum += clamp(lin, vec3(0.0), 2.0 * a.rgb);
        n = int(dz.w);
    }
    vec3 L1 = ag_estimate(0, texelFetch(ag_albedo, t, 0).rgb, sum, 1.0, 1.0);
    o_bounce = vec4(L1, 1.0);
    float y = ag_luminance(L1);
    o_accum = vec4(L1, y * y);
}
