// toth: equi-angular parametrization of a view ray seen from a point light
// (Kulla & Fajardo 2012), mirrored by st_equiangular_* in
// framework/st_physics.c. The ray point at angle theta from the foot point
// is t = t_foot + h tan(theta); since dt / d^2 = dtheta / h the in-scattering
// integrand becomes sigma_s phase I / h e^(-sigma_t (t + d)) dtheta, bounded
// and smooth, so the 1/d^2 peak of a light in view costs nothing extra.
// Angles are counted from the ray start: delta in [0, len].
#ifndef TOTH_EQUIANGULAR_GLSL
#define TOTH_EQUIANGULAR_GLSL
#include "common/uniforms.glsl"
#include "common/physics.glsl"

struct toth_eq {
    float h;   // light-ray distance, at least h_min
    float a;   // ray start relative to the foot point (-t_foot)
    float D;   // sqrt(h^2 + a^2): light distance from the ray start
    float len; // angle the segment [0, s] subtends at the light
};

// The smallest light-ray distance: a quarter of a full-resolution pixel at
// the light's distance. 1/h averaged over a disk of radius r is 2/r, so a
// ray through the light reads the average over a half-pixel disk around it
// and stays finite (also for a light at the camera: near plane).
float toth_eq_hmin(float D) {
    float pixel = 2.0 * tan(0.5 * st_fov_y) / st_resolution.y;
    return 0.25 * pixel * max(D, st_near);
}

toth_eq toth_eq_frame(vec3 o, vec3 dir, float s, vec3 light) {
    vec3 rel = light - o;
    toth_eq e;
    e.a = -dot(rel, dir);
    // |rel x dir| does not cancel the way sqrt(|rel|^2 - t_foot^2) does.
    e.h = max(length(cross(rel, dir)), toth_eq_hmin(length(rel)));
    e.D = sqrt(e.h * e.h + e.a * e.a);
    // atan(b/h) - atan(a/h), b = s + a, as one atan2.
    e.len = s > 0.0 ? atan(e.h * s, e.h * e.h + e.a * (s + e.a)) : 0.0;
    return e;
}

// Ray distance t and light distance d at angle delta: the denominator is
// D cos(theta) > 0 for every theta in (-pi/2, pi/2).
void toth_eq_point(toth_eq e, float delta, out float t, out float d) {
    float sn = sin(delta), cs = cos(delta);
    float dcos = max(e.h * cs - e.a * sn, 1e-30);
    t = e.D * e.D * sn / dcos;
    d = e.h * e.D / dcos;
}

// The angular integrand without sigma_s I / h: phase e^(-sigma_t (t + d)).
vec3 toth_eq_integrand(toth_eq e, float delta, vec3 sigma_t) {
    float t, d;
    toth_eq_point(e, delta, t, d);
    float c = -(t + e.a) / d; // toward the light, against the view ray
    return st_phase(st_phase_kind, c, st_phase_g) * exp(-sigma_t * (t + d));
}

vec3 toth_eq_panels(toth_eq e, float lo, float hi, int panels, vec3 sigma_t) {
    const vec2 x = vec2(0.339981043584856, 0.861136311594053);
    const vec2 w = vec2(0.652145154862546, 0.347854845137454);
    float pw = (hi - lo) / float(panels);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < panels; k++) {
        float mid = lo + (float(k) + 0.5) * pw;
        for (int n = 0; n < 2; n++) {
            float o = 0.5 * pw * x[n];
            sum += w[n] * (toth_eq_integrand(e, mid - o, sigma_t) + toth_eq_integrand(e, mid + o, sigma_t));
        }
    }
    return 0.5 * pw * sum;
}

// The unshadowed in-scattered radiance of light l along o + t dir, t in
// [0, s]: Gauss-Legendre in theta, ceil(nodes / 4) panels of 4 nodes, split
// at the foot point in proportion to the angles (C: st_inscatter_equiangular).
vec3 toth_eq_unshadowed(vec3 o, vec3 dir, float s, int l, int nodes, vec3 sigma_s, vec3 sigma_t) {
    toth_eq e = toth_eq_frame(o, dir, s, st_light_pos[l]);
    if (!(e.len > 0.0)) return vec3(0.0);
    int panels = max((nodes + 3) / 4, 1);
    float foot = atan(-e.a, e.h);
    vec3 sum;
    if (panels >= 2 && foot > 0.0 && foot < e.len) {
        int before = clamp(int(floor(float(panels) * foot / e.len + 0.5)), 1, panels - 1);
        sum = toth_eq_panels(e, 0.0, foot, before, sigma_t) + toth_eq_panels(e, foot, e.len, panels - before, sigma_t);
    } else {
        sum = toth_eq_panels(e, 0.0, e.len, panels, sigma_t);
    }
    return sigma_s * st_light_intensity[l] / e.h * sum;
}
#endif
