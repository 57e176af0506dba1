// toth pass 1: march each view ray (at march resolution). sampling=uniform
// writes the in-scattered radiance of the pixel's share of the steps and the
// marched length; sampling=equiangular writes each light's visible fraction
// (divided by M^2 when interleaved, so the gather's sum is their mean).
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
layout(location = 0) out vec4 o_march;

void main() {
    ivec2 lp = ivec2(gl_FragCoord.xy);
    ivec2 fp = toth_full_pixel(lp);
    vec4 gb = texelFetch(st_gbuffer, fp, 0);
    float s = toth_ray_length(gb, fp);
    int M = max(toth_interleave, 1);
    int first = (lp.x % M) + M * (lp.y % M);
    vec3 sigma_t = st_sigma_s + st_sigma_a;
#if !ST_DENSITY_VARIES // a varying density is marched (toth.c sets sampling=uniform)
    if (toth_sampling == 1) {
        float u = toth_jitter != 0 ? toth_noise(fp) : 0.5;
        o_march = toth_visible_fraction(st_cam_pos, toth_view_dir(fp), s, toth_samples, first, M * M, u, toth_bisect, sigma_t) /
                  float(M * M);
        return;
    }
#endif
    float u = toth_jitter != 0 ? toth_noise(fp) : st_step_sample_offset(toth_integrator);
#if ST_DENSITY_VARIES
    vec3 L = toth_march_density(st_cam_pos, toth_view_dir(fp), s, toth_samples, first, M * M, u, toth_integrator, sigma_t);
#else
    vec3 L = toth_march(st_cam_pos, toth_view_dir(fp), s, toth_samples, first, M * M, u, toth_integrator, sigma_t);
#endif
    o_march = vec4(L, s);
}
