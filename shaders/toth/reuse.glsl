// toth, reuse=on: a jittered frame of a box-filtered still does not march.
// The accumulation's first frame kept its per-pixel visible fraction and its
// gbuffer (the keep pass); a jittered ray reads that fraction at its own
// position in the first frame's image, bilinear among the four pixel centres
// around it that show the same surface (depth-aware, as toth/upsample.glsl),
// else from the one nearest in distance (a silhouette pixel whose jittered
// ray hits a surface none of them shows). Within a pixel the fraction is so
// interpolated, not marched again: a shaft's edge inside a pixel averages
// toward the pixel's mean instead of aliasing.
#ifndef TOTH_REUSE_GLSL
#define TOTH_REUSE_GLSL
#include "toth/common.glsl"
uniform sampler2D toth_first_tex;     // the first frame's fractions, full resolution
uniform sampler2D toth_first_gbuffer; // the first frame's gbuffer
uniform mat4 toth_first_view_proj;    // the first frame's (jittered) view-projection

vec4 toth_first_fraction(ivec2 p, vec4 g) {
    ivec2 size = textureSize(toth_first_tex, 0);
    // This frame's ray through p, in the first frame's window coordinates
    // (a sub-pixel jitter moves the image, not the eye: any point of the ray).
    vec2 ndc = (vec2(p) + 0.5) / st_resolution * 2.0 - 1.0;
    vec4 a = st_inv_view_proj * vec4(ndc, 0.0, 1.0);
    vec4 c = toth_first_view_proj * a;
    vec2 x = (c.xy / c.w * 0.5 + 0.5) * st_resolution - 0.5;
    ivec2 b = ivec2(floor(x));
    vec2 fr = x - vec2(b);
    float s = toth_ray_length(g, p), wsum = 0.0, best = 1e30;
    vec4 sum = vec4(0.0), nearest = vec4(1.0);
    for (int k = 0; k < 4; k++) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(b + o, ivec2(0), size - 1);
        vec4 gq = texelFetch(toth_first_gbuffer, q, 0);
        vec4 v = texelFetch(toth_first_tex, q, 0);
        float bil = (o.x == 1 ? fr.x : 1.0 - fr.x) * (o.y == 1 ? fr.y : 1.0 - fr.y);
        if (toth_similar(g, gq)) {
            sum += (bil + 1e-3) * v;
            wsum += bil + 1e-3;
        }
        float diff = abs(toth_ray_length(gq, q) - s) + ((g.w < 0.0) != (gq.w < 0.0) ? 1e20 : 0.0);
        if (diff < best) {
            best = diff;
            nearest = v;
        }
    }
    return wsum > 0.0 ? sum / wsum : nearest;
}
#endif
