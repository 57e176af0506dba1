// Single scattering along a view ray in the homogeneous medium:
//   integral_0^s e^(-sigma_t t) sigma_s phase(theta) E(t) e^(-sigma_t path(t)) V(t) dt
// summed over the lights, E the light's irradiance at the point (I/d^2 for a
// point light, times the cone's falloff for a spot, constant for a
// directional light) and path its way through the medium (st_light_incident).
//
// Directional lights have no 1/d^2 peak: strata uniform in t. Point and spot
// lights:
// Method: a stratified march per light, stratified in the light's angle
// (equi-angular, Kulla & Fajardo 2012) instead of in t. With h the light's
// distance from the ray's line and t0 its foot point, t = t0 + h tan(a); the
// angle range [a(0), a(s)] is cut into N equal strata and each sample takes
// one uniformly jittered angle per stratum (fresh jitter per sample), with an
// exact shadow ray per point. dt = d^2/h da cancels the 1/d^2 peak, so the
// integrand left in a is smooth and bounded (constant without extinction,
// phase and shadows): an unbiased estimate for every phase function and any
// visibility, with far less noise than strata uniform in t. A light on the
// ray's line (h ~ 0) falls back to strata uniform in t.
#include "ref.h"
#include <math.h>
#include "st_vec3.h"

// The integrand at ray distance t for light i, times `weight`: dt / d^2 for
// point and spot lights (the 1/d^2 is folded into the equi-angular weight), dt
// for directional lights.
static void source(const st_ref_geometry *g, const double origin[3], const double dir[3], int i,
                   const double sigma_s[3], const double sigma_t[3], double t, double weight,
                   double out[3]) {
    const st_medium_desc *m = &g->desc->medium;
    double x[3] = {origin[0] + t * dir[0], origin[1] + t * dir[1], origin[2] + t * dir[2]};
    st_incident in;
    if (!st_light_incident(&g->desc->lights[i], g->light_entry[i], x, &in)) return;
    const double unfold = isfinite(in.dist) ? in.dist * in.dist : 1.0;
    // cos theta between the light's travel direction and the direction toward
    // the camera (docs/physics.md): dot(normalize(light - x), view ray direction).
    double ph = st_phase_eval(m->phase, st_dot3(in.to_light, dir), m->g);
    double w[3], any = 0.0;
    for (int c = 0; c < 3; c++) {
        w[c] = weight * unfold * exp(-sigma_t[c] * (t + in.path)) * sigma_s[c] * ph * in.E[c];
        any += w[c];
    }
    if (!(any > 0.0) || !st_ref_light_visible(g, x, x, &in)) return;
    for (int c = 0; c < 3; c++)
        out[c] += w[c];
}

void st_ref_inscatter(const st_ref_geometry *g, const st_ref_options *o, const double origin[3],
                      const double dir[3], double s, st_ref_rng *rng, double out[3]) {
    out[0] = out[1] = out[2] = 0.0;
    const st_scene *sc = g->desc;
    const st_medium_desc *m = &sc->medium;
    if (!m->present || !(s > 0.0)) return;
    double sigma_s[3], sigma_t[3];
    for (int c = 0; c < 3; c++) {
        sigma_s[c] = m->sigma_s[c];
        sigma_t[c] = m->sigma_s[c] + (double)m->sigma_a[c];
    }
    if (sigma_s[0] == 0.0 && sigma_s[1] == 0.0 && sigma_s[2] == 0.0) return;
    const int n = o->march_steps > 0 ? o->march_steps : 256;
    for (int i = 0; i < sc->num_lights; i++) {
        const st_light_desc *l = &sc->lights[i];
        if (l->type == ST_LIGHT_DIRECTIONAL) {
            const double dt = s / n;
            for (int k = 0; k < n; k++)
                source(g, origin, dir, i, sigma_s, sigma_t, (k + st_ref_rng_uniform(rng)) * dt, dt,
                       out);
            continue;
        }
        double to_l[3] = {l->position[0] - origin[0], l->position[1] - origin[1],
                          l->position[2] - origin[2]};
        double t0 = st_dot3(to_l, dir);
        double h2 = st_dot3(to_l, to_l) - t0 * t0, h = sqrt(fmax(h2, 0.0));
        if (h > 1e-6 * (fabs(t0) + s)) {
            double a0 = atan2(-t0, h), a1 = atan2(s - t0, h), da = (a1 - a0) / n;
            for (int k = 0; k < n; k++) {
                double a = a0 + (k + st_ref_rng_uniform(rng)) * da;
                // dt / d^2 = da / h: the 1/d^2 of the integrand is folded in.
                source(g, origin, dir, i, sigma_s, sigma_t, t0 + h * tan(a), da / h, out);
            }
        } else {
            double dt = s / n;
            for (int k = 0; k < n; k++) {
                double t = (k + st_ref_rng_uniform(rng)) * dt;
                double d2 = (t - t0) * (t - t0) + h2;
                if (d2 > 0.0) source(g, origin, dir, i, sigma_s, sigma_t, t, dt / d2, out);
            }
        }
    }
}
