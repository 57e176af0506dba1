// toth pass 2 (interleave M > 1): each pixel sums the step shares of the
// pixels around it. Any M consecutive pixels of a row hold every residue
// once; the window is centred on the pixel (for even M, M + 1 wide with half
// weight at both ends, whose residues coincide), so every share counts once
// in all and the estimate has no half-pixel shift. Neighbours on another
// surface (distance or normal) are left out and the sum rescaled by
// M^2 / (weight kept), so no block pattern and no bleeding remain.
#include "common/uniforms.glsl"
#include "toth/common.glsl"
uniform sampler2D st_gbuffer;
uniform sampler2D toth_march_tex;
uniform int toth_interleave;
uniform int toth_sampling; // 1: four visible fractions, all summed
layout(location = 0) out vec4 o_gather;

void main() {
    ivec2 lp = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(toth_march_tex, 0);
    int M = max(toth_interleave, 1);
    int half_w = M / 2;
    bool even = (M & 1) == 0;
    // Offsets -half_w .. half_w - (odd M: 0); at the image border the window
    // is shifted inward, not clipped, so it stays whole.
    int span = even ? 2 * half_w : M - 1;
    ivec2 start = clamp(lp - half_w, ivec2(0), max(size - 1 - span, ivec2(0)));
    vec4 gc = texelFetch(st_gbuffer, toth_full_pixel(lp), 0);
    vec4 sum = vec4(0.0);
    float kept = 0.0;
    for (int dy = 0; dy <= span; dy++) {
        float wy = even && (dy == 0 || dy == span) ? 0.5 : 1.0;
        for (int dx = 0; dx <= span; dx++) {
            ivec2 q = start + ivec2(dx, dy);
            if (q.x >= size.x || q.y >= size.y) continue;
            if (q != lp && !toth_similar(gc, texelFetch(st_gbuffer, toth_full_pixel(q), 0))) continue;
            float w = wy * (even && (dx == 0 || dx == span) ? 0.5 : 1.0);
            sum += w * texelFetch(toth_march_tex, q, 0);
            kept += w;
        }
    }
    sum *= float(M * M) / max(kept, 1e-6);
    o_gather = toth_sampling == 1 ? sum : vec4(sum.rgb, texelFetch(toth_march_tex, lp, 0).a);
}
