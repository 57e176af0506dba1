// toth: a point light's unshadowed in-scattering along a view ray from the
// airlight table (modules/toth/airlight.h: Sun et al. 2005's F(u, v),
// generalised to the scene's phase function and written so that no exponent
// is positive). Two bilinear lookups per channel replace the Gauss-Legendre
// nodes of toth_eq_unshadowed; spots (whose falloff depends on the ray's
// geometry) keep the quadrature.
#ifndef TOTH_AIRLIGHT_GLSL
#define TOTH_AIRLIGHT_GLSL
#include "toth/equiangular.glsl"

uniform sampler2D toth_airlight_tex; // G: columns xi, rows u (airlight.c's grid)
const float TOTH_AIRLIGHT_U0 = 1.0;  // TOTH_AIRLIGHT_U0 of airlight.h

// G(u, xi), the grid inverted: xi = pi/2 (1 - (1 - y)^2), sqrt(u / U0) = x / (1 - x).
float toth_airlight_G(float u, float xi) {
    vec2 n = vec2(textureSize(toth_airlight_tex, 0));
    float q = sqrt(max(u, 0.0) / TOTH_AIRLIGHT_U0);
    vec2 f = vec2(1.0 - sqrt(max(1.0 - xi / (0.5 * ST_PI), 0.0)), q / (1.0 + q));
    return texture(toth_airlight_tex, (f * (n - 1.0) + 0.5) / n).r;
}

// The angular integral of toth_eq_integrand over [0, e.len] for a point
// light (C: toth_airlight_inscatter).
vec3 toth_airlight(toth_eq e, float s, vec3 sigma_t) {
    float xa = 0.25 * ST_PI + 0.5 * atan(e.a, e.h);
    float xb = min(xa + 0.5 * e.len, 0.5 * ST_PI);
    float b = s + e.a;
    float Db = sqrt(e.h * e.h + b * b);
    vec3 r;
    for (int c = 0; c < 3; c++) {
        float u = sigma_t[c] * e.h;
        r[c] = exp(-sigma_t[c] * e.D) * toth_airlight_G(u, xa) - exp(-sigma_t[c] * (s + Db)) * toth_airlight_G(u, xb);
    }
    return max(2.0 * r, 0.0); // the two lookups' interpolation may cross below 0
}

// toth_eq_unshadowed with point lights from the table. Only when the scene
// has suns or spots is the quadrature compiled in (llvmpipe pays for both
// sides of a branch).
vec3 toth_unshadowed(vec3 o, vec3 dir, float s, int l, int nodes, vec3 sigma_s, vec3 sigma_t) {
    if (ST_LIGHT_IS(l, 0)) {
        toth_eq e = toth_light_frame(o, dir, s, l);
        return e.len > 0.0 ? sigma_s * st_light_intensity[l] / e.h * toth_airlight(e, s, sigma_t) : vec3(0.0);
    }
#if (ST_LIGHT_TYPES & 6) != 0
    return toth_eq_unshadowed(o, dir, s, l, nodes, sigma_s, sigma_t);
#else
    return vec3(0.0);
#endif
}
#endif
