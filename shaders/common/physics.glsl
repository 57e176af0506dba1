// The radiometric model shared with framework/st_physics.c (DESIGN.md):
// normalized phase functions and the integration of one march step. Keep the
// two in step: tests/toth evaluates these functions on the GPU against the C.
#ifndef ST_PHYSICS_GLSL
#define ST_PHYSICS_GLSL
const float ST_PI = 3.14159265358979323846;

float st_phase_isotropic() { return 1.0 / (4.0 * ST_PI); }

float st_phase_rayleigh(float cos_theta) {
    float c = clamp(cos_theta, -1.0, 1.0);
    return 3.0 / (16.0 * ST_PI) * (1.0 + c * c);
}

// Henyey-Greenstein, normalized; g clamped to |g| <= 0.999 and the base to
// >= 0 before pow so no NaN can appear. The base 1 + g^2 - 2 g cos is written
// as (1 - g)^2 + 2 g (1 - cos): in float the textbook form cancels near the
// peak at |g| -> 1 (g = 0.999: values off by 10%, integral 0.965), while
// 1 - g and 1 - cos are exact there (integral 1.0000003).
float st_phase_hg(float cos_theta, float g) {
    g = clamp(g, -0.999, 0.999);
    float c = clamp(cos_theta, -1.0, 1.0);
    float base = g >= 0.0 ? (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - c)
                          : (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + c);
    base = max(base, 1e-30);
    return (1.0 - g * g) / (4.0 * ST_PI * base * sqrt(base));
}

// kind: 0 isotropic, 1 Rayleigh, 2 HG (st_phase_kind). cos_theta =
// dot(normalize(light - x), view ray direction): g > 0 is brightest looking
// into the light.
float st_phase(int kind, float cos_theta, float g) {
    if (kind == 1) return st_phase_rayleigh(cos_theta);
    if (kind == 2) return st_phase_hg(cos_theta, g);
    return st_phase_isotropic();
}

// (1 - e^(-sigma_t dt)) / sigma_t per channel, with the limit dt as sigma_t
// -> 0 (C: st_step_transfer). Below x = sigma_t dt = 0.1 the series of
// (1 - e^-x) / x to x^4 (error < x^5/720 = 1.4e-8) is used: in float,
// 1 - exp(-x) cancels to ~6e-8 / x relative there.
vec3 st_step_transfer(vec3 sigma_t, float dt) {
    vec3 x = sigma_t * dt;
    vec3 series = dt * (1.0 - x / 2.0 * (1.0 - x / 3.0 * (1.0 - x / 4.0 * (1.0 - x / 5.0))));
    vec3 direct = (1.0 - exp(-x)) / max(sigma_t, vec3(1e-30));
    return mix(direct, series, lessThan(x, vec3(0.1)));
}

// Energy-conserving step (Hillaire 2015): a source S constant over a step of
// length dt whose start has transmittance T contributes T S transfer.
vec3 st_step_inscatter(vec3 S, vec3 sigma_t, float dt) { return S * st_step_transfer(sigma_t, dt); }

// e^(-sigma_t d) per channel: the transmittance of a path of length d
// (C: st_transmittance).
vec3 st_transmittance(vec3 sigma_t, float d) { return exp(-sigma_t * d); }

// Integrators (C: st_integrator).
const int ST_INTEGRATOR_ENERGY = 0;
const int ST_INTEGRATOR_THESIS = 1;     // Riemann sum, source at the near end
const int ST_INTEGRATOR_THESIS_FAR = 2; // Riemann sum, source at the far end

// Where in a step [t0, t0 + dt] an integrator takes its sample (fraction of
// dt) when it is not jittered: the midpoint for the energy step (second
// order for a varying source), the ends for the thesis' Riemann sums.
float st_step_sample_offset(int integrator) {
    return integrator == ST_INTEGRATOR_THESIS ? 0.0 : integrator == ST_INTEGRATOR_THESIS_FAR ? 1.0 : 0.5;
}

// The weight w of one step of a march from the camera through a homogeneous
// medium, so that the step adds w * S(ts) with S the source (radiance per
// metre) sampled at distance ts in [t0, t0 + dt]. The transmittance to the
// step is e^(-sigma_t t0) in closed form, so steps are independent (the
// thesis' remark) and can be split over pixels. For a constant source this
// sums to C's st_march_constant: energy for any ts (exact), thesis with ts at
// the step's near end, thesis_far at its far end (T(ts) S dt).
vec3 st_step_weight(int integrator, vec3 sigma_t, float t0, float dt, float ts) {
    if (integrator == ST_INTEGRATOR_ENERGY) return exp(-sigma_t * t0) * st_step_transfer(sigma_t, dt);
    return exp(-sigma_t * ts) * dt;
}
#endif
