// toth's edges pass, march step: each fragment marches the listed pixel of
// its grid cell (toth/edges_list.glsl) at full resolution, as the march does
// at reduced resolution (the same call and inputs as a full-resolution
// march of that pixel), into toth.refined; cells past the list's end return.
#include "common/uniforms.glsl"
#include "toth/common.glsl"
#include "toth/visibility.glsl"
#include "toth/edges_list.glsl"
uniform sampler2D st_gbuffer;
uniform int toth_samples; // visibility steps of a refined pixel
uniform int toth_jitter;
uniform int toth_bisect;
layout(rgba32f, binding = 0) uniform writeonly image2D toth_refined_img;

void main() {
    int i = toth_edges_index(ivec2(gl_FragCoord.xy));
    if (i >= int(toth_edges_count)) return;
    uint e = toth_edges_list[i];
    ivec2 p = ivec2(e & 0xffffu, e >> 16);
    vec4 g = texelFetch(st_gbuffer, p, 0);
    vec3 sigma_t = st_sigma_s + st_sigma_a;
    float u = toth_jitter != 0 ? toth_noise(p) : 0.5;
    imageStore(toth_refined_img, p,
               toth_visible_fraction(st_cam_pos, toth_view_dir(p), toth_ray_length(g, p), toth_samples, 0, 1, u,
                                     toth_bisect, sigma_t));
}
