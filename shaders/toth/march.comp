// toth pass 1: march each view ray (at march resolution). sampling=uniform
// writes the in-scattered radiance of the pixel's share of the steps and the
// marched length; sampling=equiangular writes each light's visible fraction
// (divided by M^2 when interleaved, so the gather's sum is their mean).
// A compute dispatch of 8 x 8 texel groups, not a fullscreen draw: llvmpipe
// hands a draw's 64 x 64 pixel tiles to its threads, so a quarter-resolution
// march of 320x240 (80 x 60 texels) is two tiles of 3840 and 960 rays and
// one thread waits for the other; 80 groups spread evenly.
#include "common/uniforms.glsl"
#include "toth/source.glsl"
#include "toth/march.glsl"
#include "toth/march_density.glsl"
#include "toth/visibility.glsl"
#include "toth/common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) uniform writeonly image2D toth_march_img;
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

void main() {
    ivec2 lp = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(lp, imageSize(toth_march_img)))) return;
    imageStore(toth_march_img, lp, toth_march_texel(lp));
}
