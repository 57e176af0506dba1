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

// Light kinds through ST_LIGHT_TYPES (common/uniforms.glsl): a test for a
// type the scene lacks folds to false and its code compiles out (llvmpipe
// pays for both sides of a branch on a uniform).
#define TOTH_KIND_IS(k, t) ((ST_LIGHT_TYPES & (1 << (t))) != 0 && (k) == (t))

struct toth_eq {
    float h;   // light-ray distance, at least h_min
    float a;   // ray start relative to the foot point (-t_foot)
    float D;   // sqrt(h^2 + a^2): light distance from the ray start
    float len; // angle the segment [0, s] subtends at the light
    // Light types (st_light_type): a spot multiplies the integrand by glTF's
    // falloff; a directional light is parametrized by t itself (delta = t,
    // len = s, h = 1) with path(t) = max(0, path0 - slope t) and a constant
    // phase angle.
    int kind;
    vec3 o, dir, lp, axis;
    vec2 spot; // falloff scale, offset (in cos)
    float path0, slope, c;
};

// The smallest light-ray distance: a quarter of a full-resolution pixel at
// the light's distance. 1/h averaged over a disk of radius r is 2/r, so a
// ray through the light reads the average over a half-pixel disk around it
// and stays finite (also for a light at the camera: near plane).
// toth_glow's sub-rays each stand for a cell 1/n of a pixel wide: their
// bound shrinks with it (toth_eq_hmin_pixels = 0.25 / n there).
float toth_eq_hmin_pixels = 0.25;
float toth_eq_hmin(float D) {
    float pixel = 2.0 * tan(0.5 * st_fov_y) / st_resolution.y;
    return toth_eq_hmin_pixels * pixel * max(D, st_near);
}

toth_eq toth_eq_frame(vec3 o, vec3 dir, float s, vec3 light) {
    vec3 rel = light - o;
    toth_eq e;
    e.kind = 0;
    e.o = o, e.dir = dir, e.lp = light, e.axis = vec3(0.0), e.spot = vec2(0.0);
    e.path0 = e.slope = e.c = 0.0;
    e.a = -dot(rel, dir);
    // |rel x dir| does not cancel the way sqrt(|rel|^2 - t_foot^2) does.
    e.h = max(length(cross(rel, dir)), toth_eq_hmin(length(rel)));
    e.D = sqrt(e.h * e.h + e.a * e.a);
    // atan(b/h) - atan(a/h), b = s + a, as one atan2.
    e.len = s > 0.0 ? atan(e.h * s, e.h * e.h + e.a * (s + e.a)) : 0.0;
    return e;
}

// The frame of light l for the ray o + t dir, t in [0, s].
toth_eq toth_light_frame(vec3 o, vec3 dir, float s, int l) {
    if (!ST_LIGHT_IS(l, 1)) {
        toth_eq e = toth_eq_frame(o, dir, s, st_light_pos[l]);
        e.kind = st_light_type[l];
        e.axis = st_light_dir[l];
        e.spot = st_light_shape[l].xy;
        return e;
    }
    toth_eq e;
    vec3 L = -st_light_dir[l];
    e.kind = 1;
    e.h = 1.0, e.a = 1.0, e.D = 1.0, e.len = max(s, 0.0);
    e.o = o, e.dir = dir, e.lp = vec3(0.0), e.axis = L, e.spot = vec2(0.0);
    e.path0 = st_light_shape[l].z - dot(o, L);
    e.slope = dot(dir, L);
    e.c = dot(L, dir);
    return e;
}

// Ray distance t and light distance d at angle delta (directional: t =
// delta, d = the path through the medium): the denominator is D cos(theta)
// > 0 for every theta in (-pi/2, pi/2).
void toth_eq_point(toth_eq e, float delta, out float t, out float d) {
    if (TOTH_KIND_IS(e.kind, 1)) {
        t = delta;
        d = max(0.0, e.path0 - e.slope * delta);
        return;
    }
    float sn = sin(delta), cs = cos(delta);
    float dcos = max(e.h * cs - e.a * sn, 1e-30);
    t = e.D * e.D * sn / dcos;
    d = e.h * e.D / dcos;
}

// toth_eq_point inverted: the angle delta of the ray point at distance t
// (tan(delta) = h t / (h^2 + a (t + a)); directional: delta = t).
float toth_eq_angle(toth_eq e, float t) {
    if (TOTH_KIND_IS(e.kind, 1)) return t;
    return atan(e.h * t, e.h * e.h + e.a * (t + e.a));
}

// The angular integrand without sigma_s I / h: phase e^(-sigma_t (t + d)).
vec3 toth_eq_integrand(toth_eq e, float delta, vec3 sigma_t) {
    float t, d;
    toth_eq_point(e, delta, t, d);
    if (TOTH_KIND_IS(e.kind, 1)) return st_phase(st_phase_kind, e.c, st_phase_g) * exp(-sigma_t * (t + d));
    float c = -(t + e.a) / d; // toward the light, against the view ray
    float f = 1.0;
    if (TOTH_KIND_IS(e.kind, 2)) { // spot: glTF's falloff around the axis
        vec3 from_light = normalize(e.o + t * e.dir - e.lp);
        float a = clamp(dot(from_light, e.axis) * e.spot.x + e.spot.y, 0.0, 1.0);
        f = a * a;
    }
    return st_phase(st_phase_kind, c, st_phase_g) * exp(-sigma_t * (t + d)) * f;
}

// A directional light's unshadowed in-scatter in closed form: with path(t)
// = max(0, p0 - k t), integral_0^s e^(-sigma_t t) e^(-sigma_t path(t)) dt is
// e^(-sigma_t p0) integral_A e^(-sigma_t (1 - k) t) dt + integral_B
// e^(-sigma_t t) dt, A where the path is positive, B where it is 0.
vec3 toth_sun_closed(toth_eq e, vec3 sigma_t) {
    float s = e.len, p0 = e.path0, k = e.slope;
    float a0 = 0.0, a1 = 0.0; // A = [a0, a1]; B is the rest of [0, s]
    if (abs(k) < 1e-7) {
        a1 = p0 > 0.0 ? s : 0.0;
    } else {
        float tb = clamp(p0 / k, 0.0, s);
        if (k > 0.0) a0 = 0.0, a1 = p0 > 0.0 ? tb : 0.0;
        else a0 = p0 > 0.0 ? 0.0 : tb, a1 = s;
    }
    vec3 m = sigma_t * (1.0 - k);
    vec3 A = a1 > a0 ? exp(-sigma_t * p0 - m * a0) * st_step_transfer(m, a1 - a0) : vec3(0.0);
    // B: [0, a0] and [a1, s].
    vec3 B = st_step_transfer(sigma_t, a0) + exp(-sigma_t * a1) * st_step_transfer(sigma_t, s - a1);
    return st_phase(st_phase_kind, e.c, st_phase_g) * (A + B);
}

vec3 toth_eq_panels(toth_eq e, float lo, float hi, int panels, vec3 sigma_t) {
    const vec2 x = vec2(0.339981043584856, 0.861136311594053);
    const vec2 w = vec2(0.652145154862546, 0.347854845137454);
    float pw = (hi - lo) / float(max(panels, 1)); // 0 panels: an empty interval, 0
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
    toth_eq e = toth_light_frame(o, dir, s, l);
    if (!(e.len > 0.0)) return vec3(0.0);
    if (TOTH_KIND_IS(e.kind, 1)) return sigma_s * st_light_intensity[l] * toth_sun_closed(e, sigma_t);
    // A spot's cone edges are kinks in the integrand: twice the panels.
    int panels = max((nodes + 3) / 4, 1) * (TOTH_KIND_IS(e.kind, 2) ? 2 : 1);
    float foot = atan(-e.a, e.h);
    // One pair of calls, the first empty when the foot point is not inside
    // (no branch with a call on each side).
    bool split = panels >= 2 && foot > 0.0 && foot < e.len;
    int before = split ? clamp(int(floor(float(panels) * foot / e.len + 0.5)), 1, panels - 1) : 0;
    float mid = split ? foot : 0.0;
    vec3 sum = toth_eq_panels(e, 0.0, mid, before, sigma_t) + toth_eq_panels(e, mid, e.len, panels - before, sigma_t);
    return sigma_s * st_light_intensity[l] / e.h * sum;
}
#endif
