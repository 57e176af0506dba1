// The radiometric model shared with framework/st_physics.c (DESIGN.md):
// normalized phase functions and the energy-conserving march step.
#ifndef ST_PHYSICS_GLSL
#define ST_PHYSICS_GLSL
const float ST_PI = 3.14159265358979323846;

float st_phase_isotropic() { return 1.0 / (4.0 * ST_PI); }

float st_phase_rayleigh(float cos_theta) {
    return 3.0 / (16.0 * ST_PI) * (1.0 + cos_theta * cos_theta);
}

// Henyey-Greenstein, normalized; g clamped to |g| <= 0.999 and the base to
// >= 0 before pow so no NaN can appear.
float st_phase_hg(float cos_theta, float g) {
    g = clamp(g, -0.999, 0.999);
    float base = max(1.0 + g * g - 2.0 * g * cos_theta, 0.0);
    return (1.0 - g * g) / (4.0 * ST_PI * pow(max(base, 1e-12), 1.5));
}

// kind: 0 isotropic, 1 Rayleigh, 2 HG. cos_theta = dot(normalize(light - x), view dir).
float st_phase(int kind, float cos_theta, float g) {
    if (kind == 1) return st_phase_rayleigh(cos_theta);
    if (kind == 2) return st_phase_hg(cos_theta, g);
    return st_phase_isotropic();
}

// Energy-conserving step (Hillaire 2015): integrates a source S constant over
// a step of length dt with transmittance T at its start. Exact for constant S;
// the sigma_t -> 0 limit is S dt. Per channel.
vec3 st_step_inscatter(vec3 S, vec3 sigma_t, float dt) {
    vec3 res;
    for (int c = 0; c < 3; c++) {
        float st = sigma_t[c];
        float x = st * dt;
        // (1 - e^-x)/st, with a series near 0 so small sigma_t keeps precision.
        res[c] = x < 1e-4 ? S[c] * dt * (1.0 - 0.5 * x) : S[c] * (1.0 - exp(-x)) / st;
    }
    return res;
}
#endif
