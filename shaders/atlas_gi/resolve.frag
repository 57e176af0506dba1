// After each gather frame: the running mean of the indirect radiance, and the
// combined atlas (direct + emission + indirect, what the thesis textures back),
// both dilated one texel into the gutters so bilinear lookups at chart borders
// never read empty texels; plus per-texel statistics for the convergence test.
uniform sampler2D ag_pos;   // .w: area (0 in gutters)
uniform sampler2D ag_l0;
uniform sampler2D ag_accum; // sum of frame estimates, sum of luminance^2
uniform float ag_frames;
// 0 where neither the texel nor a neighbour has area: nothing but 0 to write,
// and the targets hold 0 there (atlas_gpu.c clears them once).
uniform sampler2D ag_near;
layout(location = 0) out vec4 o_indirect;
layout(location = 1) out vec4 o_combined;
layout(location = 2) out vec4 o_stats; // mean luminance, variance of the mean, valid

float lum(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(ag_pos, 0);
    if (texelFetch(ag_near, t, 0).r == 0.0) discard;
    if (texelFetch(ag_pos, t, 0).w > 0.0) {
        vec4 acc = texelFetch(ag_accum, t, 0);
        vec3 mean = acc.rgb / ag_frames;
        float m = lum(mean);
        float var = ag_frames > 1.0 ? max(acc.a / ag_frames - m * m, 0.0) / (ag_frames - 1.0) : 0.0;
        o_indirect = vec4(mean, 1.0);
        o_combined = vec4(texelFetch(ag_l0, t, 0).rgb + mean, 1.0);
        o_stats = vec4(m, var, 1.0, 0.0);
        return;
    }
    // Gutter: the average of the valid 8-neighbours (charts are >= 4 texels apart).
    vec3 ind = vec3(0.0), comb = vec3(0.0);
    float n = 0.0;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            ivec2 q = t + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            if (texelFetch(ag_pos, q, 0).w <= 0.0) continue;
            vec3 mean = texelFetch(ag_accum, q, 0).rgb / ag_frames;
            ind += mean;
            comb += texelFetch(ag_l0, q, 0).rgb + mean;
            n += 1.0;
        }
    o_indirect = vec4(n > 0.0 ? ind / n : vec3(0.0), 0.0);
    o_combined = vec4(n > 0.0 ? comb / n : vec3(0.0), 0.0);
    o_stats = vec4(0.0);
}
