// toth: the table behind the closed-form unshadowed in-scattering of a point
// light (the airlight integral of Sun et al. 2005, for any phase function).
// Along a view ray at distance h from the light, with the angle theta seen
// from the light counted from the ray's foot point, t + d = t_foot +
// h tan(xi) for xi = pi/4 + theta/2 in [0, pi/2], and the scattering angle's
// cosine is cos(2 xi). The in-scattered integral over theta of docs/physics.md
// (equiangular.glsl) is then
//   2 [e^(-sigma_t D_start) G(sigma_t h, xi_start)
//      - e^(-sigma_t (s + D_end)) G(sigma_t h, xi_end)]
// with G(u, xi) = int_xi^(pi/2) p(cos 2 z) e^(-u (tan z - tan xi)) dz: every
// exponent is <= 0, so nothing is amplified (Sun's F(u, v) with the factor
// e^(-sigma_t t_foot) outside grows where the foot point is behind the camera).
#ifndef TOTH_AIRLIGHT_H
#define TOTH_AIRLIGHT_H
#include "st_physics.h"

// Texels along xi in [0, pi/2] (columns) and along u in [0, infinity) (rows;
// the last is u = infinity, G = 0), on the grid of airlight.c; texel centres
// sit on the grid points (shaders/toth/airlight.glsl maps the same way). 1 MiB:
// against 256-node Gauss-Legendre, 1e-3 relative at most (rms 3e-5) for HG
// g <= 0.5 over random rays; 64 rows gave 3.6e-2.
#define TOTH_AIRLIGHT_NXI 1024
#define TOTH_AIRLIGHT_NU 256
#define TOTH_AIRLIGHT_U0 1.0

// Fills G[row * NXI + col] (NU x NXI floats) for the phase function
// (kind, g), by 4-node Gauss-Legendre per column interval, backward from
// xi = pi/2 (G = 0 there).
void toth_airlight_fill(float *G, st_phase_kind kind, double g);
// G(u, xi) interpolated bilinearly from the table, as the GPU samples it.
double toth_airlight_lookup(const float *G, double u, double xi);
// The unshadowed in-scattering of problem p (a point light) from the table,
// as shaders/toth/airlight.glsl evaluates it (h raised to h_min as
// st_equiangular_frame does).
double toth_airlight_inscatter(const float *G, const st_inscatter_problem *p, double h_min);
#endif
