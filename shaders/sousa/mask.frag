// Sousa depth mask (thesis listing A.6): linear camera depth divided by far,
// 1 where no surface is seen, so far = emitting. Read from the G-buffer's
// camera distance (the regular pass already rendered it) instead of drawing
// the scene again: z = distance * cos(angle between pixel ray and view axis).
// A mask texel smaller than the screen averages 4 screen pixels of its footprint.
#include "common/uniforms.glsl"
uniform sampler2D st_gbuffer;
uniform vec2 u_out_size; // mask size in texels
layout(location = 0) out vec4 o_mask;

float linear_depth(vec2 uv) {
    ivec2 px = clamp(ivec2(uv * st_resolution), ivec2(0), ivec2(st_resolution) - 1);
    float dist = texelFetch(st_gbuffer, px, 0).w;
    if (dist < 0.0) return 1.0;
    vec2 ndc = (vec2(px) + 0.5) / st_resolution * 2.0 - 1.0;
    vec4 f = st_inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 dir = normalize(f.xyz / f.w - st_cam_pos);
    vec3 fwd = -vec3(st_view[0][2], st_view[1][2], st_view[2][2]);
    return clamp(dist * dot(dir, fwd) / max(st_far, 1e-6), 0.0, 1.0);
}

void main() {
    vec2 uv = gl_FragCoord.xy / u_out_size, h = 0.25 / u_out_size;
    float m = linear_depth(uv + vec2(-h.x, -h.y)) + linear_depth(uv + vec2(h.x, -h.y)) +
              linear_depth(uv + vec2(-h.x, h.y)) + linear_depth(uv + vec2(h.x, h.y));
    o_mask = vec4(0.25 * m, 0.0, 0.0, 1.0);
}
