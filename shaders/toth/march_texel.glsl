// toth pass 1, the march of one texel (march.frag draws it, march.comp
// dispatches it): each view ray at march resolution. sampling=uniform
// gives the in-scattered radiance of the pixel's share of the steps and the
// marched length; sampling=equiangular each light's visible fraction
// (divided by M^2 when interleaved, so the gather's sum is their mean).
#ifndef TOTH_MARCH_TEXEL_GLSL
#define TOTH_MARCH_TEXEL_GLSL
#include "common/uniforms.glsl"
#include "toth/source.glsl"
#include "toth/march.glsl"
#include "toth/march_density.glsl"
#include "toth/visibility.glsl"
#include "toth/common.glsl"
uniform sampler2D st_gbuffer;
uniform int toth_samples;    // steps per ray
uniform int toth_interleave; // M: steps split over M x M pixel blocks
uniform int toth_jitter;
uniform int toth_integrator;
uniform int toth_sampling; // 0 uniform, 1 equiangular
uniform int toth_bisect;   // equiangular: halvings per shadow boundary

vec4 toth_march_texel(ivec2 lp) {
    ivec2 fp = toth_full_pixel(lp);
    vec4 gb = texelFetch(st_gbuffer, fp, 0);
    float s = toth_ray_length(gb, fp);
    int M = max(toth_interleave, 1);
    int first = (lp.x % M) + M * (lp.y % M);
    vec3 sigma_t = st_sigma_s + st_sigma_a;
#if !ST_DENSITY_VARIES // a varying density is marched (toth.c sets sampling=uniform)
    if (toth_sampling == 1) {
        float u = toth_jitter != 0 ? toth_noise(fp) : 0.5;
        return toth_visible_fraction(st_cam_pos, toth_view_dir(fp), s, toth_samples, first, M * M, u, toth_bisect, sigma_t) /
               float(M * M);
    }
#endif
    float u = toth_jitter != 0 ? toth_noise(fp) : st_step_sample_offset(toth_integrator);
#if ST_DENSITY_VARIES
    vec3 L = toth_march_density(st_cam_pos, toth_view_dir(fp), s, toth_samples, first, M * M, u, toth_integrator, sigma_t);
#else
    vec3 L = toth_march(st_cam_pos, toth_view_dir(fp), s, toth_samples, first, M * M, u, toth_integrator, sigma_t);
#endif
    return vec4(L, s);
}
#endif
