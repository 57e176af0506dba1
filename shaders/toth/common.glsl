// toth: helpers shared by the march, gather and compose passes.
#ifndef TOTH_COMMON_GLSL
#define TOTH_COMMON_GLSL
#include "common/uniforms.glsl"

uniform int toth_scale;        // march resolution divisor: 1, 2 or 4
uniform float toth_tolerance;  // relative distance difference still "the same surface"

// Interleaved gradient noise (Jimenez 2014): a fixed per-pixel offset in
// [0, 1) that turns banding into fine noise.
float toth_noise(ivec2 p) {
    return fract(52.9829189 * fract(dot(vec2(p), vec2(0.06711056, 0.00583715))));
}

// The full-resolution pixel whose ray a march-resolution pixel traces: the
// one nearest the centre of its scale x scale block.
ivec2 toth_full_pixel(ivec2 lp) {
    return min(lp * toth_scale + (toth_scale - 1) / 2, ivec2(st_resolution) - 1);
}

// March texel q reflected into the image at its border (-1 -> 1, n -> n - 2):
// the upsampling judges a tap clamped at the border by the texel mirrored
// inward (toth/upsample.glsl).
ivec2 toth_mirror(ivec2 q, ivec2 size) {
    return clamp(size - 1 - abs(size - 1 - abs(q)), ivec2(0), size - 1);
}

// Unit direction of the view ray through NDC point ndc, as the pinhole of
// docs/physics.md.
vec3 toth_ndc_dir(vec2 ndc) {
    vec4 a = st_inv_view_proj * vec4(ndc, -1.0, 1.0);
    vec4 b = st_inv_view_proj * vec4(ndc, 1.0, 1.0);
    return normalize(b.xyz / b.w - a.xyz / a.w);
}

// ... through the centre of full-resolution pixel px (GL window coordinates,
// origin bottom left).
vec3 toth_view_dir(ivec2 px) { return toth_ndc_dir((vec2(px) + 0.5) / st_resolution * 2.0 - 1.0); }

// The marched length of full-resolution pixel px: the distance to the visible
// surface, or where the pixel sees none (gbuffer w = -1) the distance to the
// far plane along its ray, far / cos(angle to the view axis), as the
// reference renderer marches it.
float toth_ray_length(vec4 gb, ivec2 px) {
    if (gb.w >= 0.0) return gb.w;
    return st_far / max(dot(toth_view_dir(px), toth_ndc_dir(vec2(0.0))), 1e-3);
}

// Do two gbuffer texels' rays end at continuous distances (within
// edge_tolerance)? Background matches background only.
bool toth_continuous(vec4 a, vec4 b) {
    bool bga = a.w < 0.0, bgb = b.w < 0.0;
    if (bga || bgb) return bga && bgb;
    return abs(a.w - b.w) <= toth_tolerance * max(a.w, b.w);
}

// Do they show the same surface closely enough to share in-scattered light:
// continuous, and (off the background) normals within ~37 degrees?
bool toth_similar(vec4 a, vec4 b) {
    return toth_continuous(a, b) && (a.w < 0.0 || dot(a.xyz, b.xyz) >= 0.8);
}
#endif
