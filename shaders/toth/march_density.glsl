// toth: the march of one view ray through a medium whose density varies
// (ST_DENSITY != 0, docs/physics.md "Heterogeneous media"). The includer
// defines toth_source(x, dir, min_d2) as for toth_march (march.glsl): the
// in-scattered radiance per metre at density 1, its light paths already
// attenuated by their optical depth (st_light_transmittance).
//
// The transmittance to a step's start is e^(-sigma_t tau(0, t0)), tau summed
// piece by piece along the ray (height fog in closed form, a grid by its exact
// DDA: common/medium.glsl). With the source constant over a step, its exact
// contribution is independent of how the density is spread inside it:
//   integral T(t) sigma_s d(t) S dt = T(t0) sigma_s / sigma_t (1 - e^(-sigma_t tau_step))
//                                   = T(t0) sigma_s d_m transfer(sigma_t d_m, dt),
// d_m = tau_step / dt the step's mean density (energy integrator; a constant
// density gives toth_march's weight). The thesis' Riemann sums weight the
// source with the density and the transmittance at the sample instead.
#ifndef TOTH_MARCH_DENSITY_GLSL
#define TOTH_MARCH_DENSITY_GLSL
#include "common/medium.glsl"
#include "toth/march.glsl"

vec3 toth_march_density(vec3 o, vec3 dir, float s, int n, int first, int stride, float u,
                        int integrator, vec3 sigma_t) {
    n = max(n, 1);
    stride = max(stride, 1);
    float dt = max(s, 0.0) / float(n);
    float min_d2 = toth_min_d2(dt);
    float tau = 0.0, done = 0.0; // optical depth of [0, done]
    vec3 L = vec3(0.0);
    for (int i = first; i < n; i += stride) {
        float t0 = float(i) * dt, ts = (float(i) + u) * dt;
        tau += st_optical_depth(o, dir, done, t0);
        float tau_step = st_optical_depth(o, dir, t0, t0 + dt);
        done = t0 + dt;
        vec3 S = toth_source(o + ts * dir, dir, min_d2);
        if (integrator == ST_INTEGRATOR_ENERGY) {
            float dm = tau_step / max(dt, 1e-30);
            L += exp(-sigma_t * tau) * S * (dm * st_step_transfer(sigma_t * dm, dt));
        } else {
            vec3 T = exp(-sigma_t * (tau + u * tau_step));
            L += T * S * (st_density(o + ts * dir) * dt);
        }
        tau = min(tau + tau_step, ST_DENSITY_MAX);
    }
    return L;
}
#endif
