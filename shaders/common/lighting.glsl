// What the lights deliver at a point, and direct light on a Lambertian
// surface, shared by the regular pass and atlas_gi's G-buffer (C:
// st_light_incident, st_direct_lambert in st_physics):
//   rho/pi E max(cos, 0) V e^(-sigma_t tau(path))
// E = I/d^2 (point), I falloff/d^2 (spot), the irradiance (directional).
// The including shader defines st_visibility (1 without shadow_map).
#ifndef ST_LIGHTING_GLSL
#define ST_LIGHTING_GLSL
#include "common/medium.glsl"

const int ST_LIGHT_POINT = 0;
const int ST_LIGHT_DIRECTIONAL = 1;
const int ST_LIGHT_SPOT = 2;

float st_visibility(int light, vec3 p, vec3 n);

struct st_incident {
    vec3 to_light; // unit, toward the light
    float dist;    // to the light (1e30: directional)
    float path;    // through the medium
    vec3 E;        // irradiance on a surface facing the light, before the medium
};

// False where nothing arrives (at the light, outside a spot's cone).
bool st_light_incident(int i, vec3 x, out st_incident r) {
    r.E = vec3(0.0);
    if (ST_LIGHT_IS(i, ST_LIGHT_DIRECTIONAL)) {
        r.to_light = -st_light_dir[i];
        r.dist = 1e30;
        r.path = max(0.0, st_light_shape[i].z - dot(x, r.to_light));
        r.E = st_light_intensity[i];
        return true;
    }
    vec3 l = st_light_pos[i] - x;
    float d2 = max(dot(l, l), 1e-12); // a light on the point: to_light = 0, no cosine
    float inv_d = inversesqrt(d2);
    r.to_light = l * inv_d;
    r.dist = r.path = d2 * inv_d;
    float f = 1.0;
    if (ST_LIGHT_IS(i, ST_LIGHT_SPOT)) {
        float a = clamp(-dot(r.to_light, st_light_dir[i]) * st_light_shape[i].x + st_light_shape[i].y, 0.0, 1.0);
        f = a * a;
        if (f <= 0.0) return false;
    }
    r.E = st_light_intensity[i] * (f / d2);
    return true;
}

vec3 st_direct_light(vec3 p, vec3 n, vec3 albedo) {
    vec3 direct = vec3(0.0);
    for (int i = 0; i < st_num_lights; i++) {
        st_incident r;
        if (!st_light_incident(i, p, r)) continue;
        float c = dot(n, r.to_light);
        if (c <= 0.0) continue;
        direct += albedo / ST_PI * r.E * c * st_visibility(i, p, n) *
                  st_light_transmittance(p, r.to_light, r.path);
    }
    return direct;
}
#endif
