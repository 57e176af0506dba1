// toth's edges pass: in the blocks edges.vert keeps, each pixel whose
// upsampling taps disagree (toth/upsample.glsl) marches its own ray at full
// resolution, as the march does at reduced resolution; the others write -1,
// which the compose pass reads as "upsample".
#include "common/uniforms.glsl"
#include "toth/common.glsl"
#include "toth/visibility.glsl"
#include "toth/upsample.glsl"
#include "toth/kink.glsl"
uniform int toth_samples; // visibility steps of a refined pixel
uniform int toth_jitter;
uniform int toth_bisect;
layout(location = 0) out vec4 o_refined;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 g = texelFetch(st_gbuffer, p, 0);
    float spread = 0.0;
    toth_upsample(p, g, spread);
    o_refined = vec4(-1.0);
    if (spread > toth_refine || toth_kinked(p / toth_scale)) {
        vec3 sigma_t = st_sigma_s + st_sigma_a;
        float u = toth_jitter != 0 ? toth_noise(p) : 0.5;
        o_refined = toth_visible_fraction(st_cam_pos, toth_view_dir(p), toth_ray_length(g, p), toth_samples, 0, 1, u,
                                          toth_bisect, sigma_t);
    }
}
