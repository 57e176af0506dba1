// toth: the single-scattering source of docs/physics.md at a point x of a view ray
// with direction dir (camera -> scene): the sum over point lights of
// sigma_s phase(theta) I V / d^2 e^(-sigma_t d), V from shadow_map.
#ifndef TOTH_SOURCE_GLSL
#define TOTH_SOURCE_GLSL
#include "common/uniforms.glsl"
#include "common/physics.glsl"
#include "shadow_map/visibility.glsl"

vec3 toth_source(vec3 x, vec3 dir, float min_d2) {
    vec3 sigma_t = st_sigma_s + st_sigma_a;
    vec3 S = vec3(0.0);
    for (int l = 0; l < st_num_lights; l++) {
        vec3 to_light = st_light_pos[l] - x;
        float d2 = dot(to_light, to_light);
        float d = sqrt(d2);
        // cos theta between the light's travel direction at x and the
        // direction toward the camera; 0 when x sits on the light.
        float c = d > 0.0 ? dot(to_light, dir) / d : 0.0;
        float v = st_visibility_point(l, x);
        if (v <= 0.0) continue;
        // Extinction first: with sigma_t d large the product underflows to
        // 0 instead of forming inf * 0.
        vec3 ext = exp(-sigma_t * d) / max(d2, min_d2);
        S += st_phase(st_phase_kind, c, st_phase_g) * v * st_light_intensity[l] * ext;
    }
    return st_sigma_s * S;
}
#endif
