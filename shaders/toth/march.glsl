// toth: the march of one view ray (Toth & Umenhoffer 2009, with the step
// integration of docs/physics.md). The includer defines the source first:
//   vec3 toth_source(vec3 x, vec3 dir, float min_d2)
// the in-scattered radiance per metre at x toward the camera (before the
// camera-side transmittance), with light distances below sqrt(min_d2)
// clamped. shaders/toth/source.glsl is the real one; tests plug in others.
#ifndef TOTH_MARCH_GLSL
#define TOTH_MARCH_GLSL
#include "common/physics.glsl"

// The smallest squared light distance a sample may see. The integral of
// 1/d^2 along a ray through the light diverges, so a sample closer than half
// a step is treated as half a step away: a step then adds at most
// 4 sigma_s phase I / dt,
// which keeps a light exactly on a pixel's ray finite without touching
// samples farther than dt/2 from it.
float toth_min_d2(float dt) { return max(0.25 * dt * dt, 1e-12); }

// Integrates steps first, first + stride, ... < n of the ray o + t dir,
// t in [0, s], split into n equal steps; u in [0, 1) is where in each step
// the source is sampled. With stride 1 this is the whole march; interleaved
// sampling gives each pixel of an MxM block one residue class (stride M^2).
// The step weight is e^(-sigma_t t) times a constant, so it is carried from
// step to step by one multiplication (exact to float rounding, ~1e-5 after
// 1024 steps) instead of an exp per step.
vec3 toth_march(vec3 o, vec3 dir, float s, int n, int first, int stride, float u, int integrator,
                vec3 sigma_t) {
    n = max(n, 1);
    stride = max(stride, 1);
    float dt = max(s, 0.0) / float(n);
    float min_d2 = toth_min_d2(dt);
    float t0 = float(first) * dt;
    vec3 w = st_step_weight(integrator, sigma_t, t0, dt, t0 + u * dt);
    vec3 decay = exp(-sigma_t * (dt * float(stride)));
    vec3 L = vec3(0.0);
    for (int i = first; i < n; i += stride) {
        float ts = (float(i) + u) * dt;
        L += w * toth_source(o + ts * dir, dir, min_d2);
        w *= decay;
    }
    return L;
}
#endif
