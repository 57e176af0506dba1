// toth: the single-scattering source of docs/physics.md at a point x of a view ray
// with direction dir (camera -> scene): the sum over the lights of
// sigma_s phase(theta) E V e^(-sigma_t tau(path)), E = I/d^2 (point), I f/d^2
// (spot), the irradiance (directional), V from shadow_map.
#ifndef TOTH_SOURCE_GLSL
#define TOTH_SOURCE_GLSL
#include "common/uniforms.glsl"
#include "common/physics.glsl"
#include "common/medium.glsl"
#include "shadow_map/visibility.glsl"

vec3 toth_source(vec3 x, vec3 dir, float min_d2) {
    vec3 sigma_t = st_sigma_s + st_sigma_a;
    vec3 S = vec3(0.0);
    for (int l = 0; l < st_num_lights; l++) {
        // What light l delivers at x (common/lighting.glsl's st_light_incident,
        // with the 1/d^2 peak bounded by min_d2 for the march).
        vec3 to_light;
        float path, c;
        vec3 E;
        if (ST_LIGHT_IS(l, 1)) { // directional: no 1/d^2, path from the entry plane
            to_light = -st_light_dir[l];
            path = max(0.0, st_light_shape[l].z - dot(x, to_light));
            c = dot(to_light, dir);
            E = st_light_intensity[l];
        } else {
            vec3 v = st_light_pos[l] - x;
            float d2 = dot(v, v);
            float d = sqrt(d2);
            // cos theta between the light's travel direction at x and the
            // direction toward the camera; 0 when x sits on the light.
            c = d > 0.0 ? dot(v, dir) / d : 0.0;
            float f = 1.0;
            if (ST_LIGHT_IS(l, 2) && d > 0.0) { // spot: glTF's falloff
                float a = clamp(-dot(v / d, st_light_dir[l]) * st_light_shape[l].x + st_light_shape[l].y, 0.0, 1.0);
                f = a * a;
            }
            path = d;
            to_light = d > 0.0 ? v / d : vec3(0.0);
            E = st_light_intensity[l] * (f / max(d2, min_d2));
        }
        if (all(equal(E, vec3(0.0)))) continue;
        float vis = st_visibility_point(l, x);
        if (vis <= 0.0) continue;
        // Extinction first: with sigma_t d large the product underflows to
        // 0 instead of forming inf * 0.
        S += st_phase(st_phase_kind, c, st_phase_g) * vis * E * st_light_transmittance(x, to_light, path);
    }
    return st_sigma_s * S;
}
#endif
