// Direct light from the point lights on a Lambertian surface, shared by the
// regular pass and atlas_gi's G-buffer (C: st_direct_point):
//   rho/pi I max(cos, 0) / d^2 V e^(-sigma_t d)
// The including shader defines st_visibility (1 without shadow_map).
#ifndef ST_LIGHTING_GLSL
#define ST_LIGHTING_GLSL
#include "common/medium.glsl"

float st_visibility(int light, vec3 p, vec3 n);

vec3 st_direct_light(vec3 p, vec3 n, vec3 albedo) {
    vec3 direct = vec3(0.0);
    for (int i = 0; i < st_num_lights; i++) {
        vec3 l = st_light_pos[i] - p;
        float d2 = max(dot(l, l), 1e-12);
        float inv_d = inversesqrt(d2);
        float c = dot(n, l) * inv_d;
        if (c <= 0.0) continue;
        direct += albedo / ST_PI * st_light_intensity[i] * (c / d2) * st_visibility(i, p, n) *
                  st_path_transmittance(d2 * inv_d);
    }
    return direct;
}
#endif
