// One bounce gathered per atlas texel from N Hammersley samples over the
// whole atlas (Merz 2010, 4.6), rotated per frame (Cranley-Patterson) for
// progressive accumulation; or from N picks drawn on the CPU in proportion
// to each texel's flux (sampling=power), each weighted by 1/(N p_j). Output 0: this bounce's indirect radiance;
// output 1 (blended additively on the last bounce): rgb and luminance^2 for
// the running mean and its variance.
#include "common/estimator.glsl"
#include "common/medium.glsl"
#ifdef AG_VISIBILITY
#include "common/bvh.glsl"
#endif
uniform sampler2D ag_pos;    // position, area
uniform sampler2D ag_normal; // normal, valid
uniform sampler2D ag_albedo;
uniform sampler2D ag_l0;     // direct + emission
uniform sampler2D ag_prev;   // the previous bounce's indirect (ag_use_prev)
uniform sampler1D ag_hammersley;
uniform sampler1D ag_picks; // power sampling: texel x, y, 1/(N p_j) per sample
uniform int ag_power;
uniform int ag_use_prev;
uniform int ag_samples;
uniform int ag_estimator;
uniform vec2 ag_rotation;
uniform float ag_offset; // visibility rays start this far off the surfaces (m)
layout(location = 0) out vec4 o_bounce;
layout(location = 1) out vec4 o_accum;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(ag_pos, 0);
    vec4 xa = texelFetch(ag_pos, t, 0);
    if (xa.w <= 0.0) { // gutter
        o_bounce = vec4(0.0);
        o_accum = vec4(0.0);
        return;
    }
    vec3 x = xa.xyz;
    vec3 nx = texelFetch(ag_normal, t, 0).xyz;
    vec3 rho = texelFetch(ag_albedo, t, 0).rgb;
    vec3 sum = vec3(0.0);
    float cells = float(size.x) * float(size.y);
    // Uniform picks weigh W H / N (the area estimator) or 1 (the thesis' 2 pi / N comes last).
    float uniform_w = ag_estimator == 1 ? 1.0 : cells / float(ag_samples);
    for (int i = 0; i < ag_samples; i++) {
        ivec2 j;
        float ws;
        if (ag_power != 0) {
            vec4 pk = texelFetch(ag_picks, i, 0);
            j = ivec2(pk.xy);
            ws = pk.z;
        } else {
            vec2 u = fract(texelFetch(ag_hammersley, i, 0).rg + ag_rotation);
            j = min(ivec2(u * vec2(size)), size - 1);
            ws = uniform_w;
        }
        vec4 pa = texelFetch(ag_pos, j, 0);
        if (pa.w <= 0.0) continue; // a gutter texel: counted in N, adds nothing
        vec3 d = pa.xyz - x;
        float d2 = dot(d, d);
        if (d2 < 1e-20) continue;
        vec3 w = d * inversesqrt(d2);
        float cx = dot(nx, w);
        if (cx <= 0.0) continue;
        vec3 nj = texelFetch(ag_normal, j, 0).xyz;
        float cj = -dot(nj, w);
        if (cj <= 0.0) continue; // both must face each other (both estimators)
        vec3 L = texelFetch(ag_l0, j, 0).rgb;
        if (ag_use_prev != 0) L += texelFetch(ag_prev, j, 0).rgb;
        if (L == vec3(0.0)) continue;
#ifdef AG_VISIBILITY
        if (st_bvh_occluded(x + nx * ag_offset, pa.xyz + nj * ag_offset)) continue;
#endif
        L *= st_path_transmittance(d2 * inversesqrt(d2)); // sender -> receiver
        sum += L * (ag_sample_weight(ag_estimator, cx, cj, pa.w, d2) * ws);
    }
    vec3 L1 = ag_estimator == 1 ? ag_estimate(1, rho, sum, cells, float(ag_samples)) : ag_estimate(0, rho, sum, 1.0, 1.0);
    o_bounce = vec4(L1, 1.0);
    float y = ag_luminance(L1);
    o_accum = vec4(L1, y * y);
}
