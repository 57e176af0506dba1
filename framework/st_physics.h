// strahl: the shared radiometric model (docs/physics.md) as
// plain C in double precision. The CPU reference renders with it, the GLSL in
// shaders/common mirrors it, and the tests compare both against the closed
// forms below.
//
// Angles: cos_theta = dot(normalize(light - x), view ray direction), i.e. the
// cosine between the light's travel direction at x and the direction toward
// the camera, so HG with g > 0 is brightest looking into the light.
#ifndef ST_PHYSICS_H
#define ST_PHYSICS_H
#include "st_scene.h"
#include <math.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ST_PI 3.14159265358979323846

// ---- Extinction on light paths ---------------------------------------------
// With a medium, every path from a light to a point (a surface point or a
// scattering point) and a diffuse bounce's path from sender to receiver is
// attenuated by e^(-sigma_t d); the view ray keeps its own e^(-sigma_t s).
// sigma_t = sigma_s + sigma_a per channel, 0 without a medium.
void st_medium_sigma_t(const st_medium_desc *m, double out[3]);
// e^(-sigma_t d) per channel (GLSL: st_transmittance).
void st_transmittance(const double sigma_t[3], double d, double out[3]);
// Direct light on a Lambertian surface of albedo rho from a point light of
// intensity I at distance d: rho/pi I max(cos, 0) / d^2 e^(-sigma_t d).
double st_direct_point(double rho, double intensity, double cos_theta, double d, double sigma_t);

// ---- Heterogeneous media (medium.density) ----------------------------------
// sigma_s(x) = sigma_s d(x), sigma_a(x) = sigma_a d(x), with d the density
// (1 for a homogeneous medium). Every path's attenuation e^(-sigma_t d)
// becomes e^(-sigma_t tau), tau the density's integral along the path (the
// optical depth per unit sigma_t). docs/physics.md "Heterogeneous media".
//
// Rays are o + t w with w a unit vector, segments t in [t0, t1].

// Whether the medium's density varies (height fog or grid).
static inline bool st_density_varies(const st_density_desc *d) {
    return d && d->kind != ST_DENSITY_UNIFORM;
}
// d(x).
double st_density_at(const st_density_desc *d, const double x[3]);
// Height fog's integral along a segment that starts at height y, climbs dy
// per metre (the ray direction's y component) and is `length` long:
//   integral_0^L e^(-k (y + dy t - y0)) dt = L d(y_low) (1 - e^(-x)) / x,
// x = k |dy| L >= 0, y_low the segment's lower end: the form never overflows
// beyond d(y_low) L, and (1 - e^(-x)) / x = -expm1(-x)/x -> 1 as x -> 0
// (horizontal rays, falloff 0) without cancellation.
double st_height_fog_integral(double base, double falloff, double y, double dy, double length);
// tau = integral_t0^t1 d(o + t w) dt: height fog in closed form; a grid by
// DDA through the cells between voxel centres, where the trilinear density
// along the line is a cubic in t that 2-point Gauss-Legendre integrates
// exactly (so tau is exact up to rounding, at most n[0] + n[1] + n[2] + 3
// cells); t1 - t0 for a homogeneous medium.
double st_density_integral(const st_density_desc *d, const double o[3], const double w[3],
                           double t0, double t1);
// Narrows [*t0, *t1] to where d can be non-zero (a grid's block); false when
// nothing is left. Height fog and uniform media keep the interval.
bool st_density_clip(const st_density_desc *d, const double o[3], const double w[3], double *t0,
                     double *t1);
// A majorant of d over the segment: d at its lower end for height fog (d
// falls with y), the largest voxel for a grid, 1 for a uniform medium.
double st_density_majorant(const st_density_desc *d, const double o[3], const double w[3],
                           double t0, double t1);
// e^(-sigma_t tau) per channel along the segment (st_transmittance for a
// uniform medium).
void st_segment_transmittance(const double sigma_t[3], const st_density_desc *d, const double o[3],
                              const double w[3], double t0, double t1, double out[3]);

// ---- Light arriving at a point ----------------------------------------------
// glTF's spot falloff (KHR_lights_punctual): with c = cos of the angle between
// the spot's axis and the direction from the light to the point,
// s = 1 / max(0.001, cos(inner) - cos(outer)), the factor is
// clamp((c - cos(outer)) s, 0, 1)^2: 1 inside the inner cone, 0 outside the outer.
double st_spot_falloff(double cos_axis, double inner, double outer);

// A directional light enters the medium at the plane, normal to its
// direction, that touches the scene's bounds on the light's side; `entry` =
// max over the bounds' corners c of dot(c, -direction). Its path to x through
// the medium is then max(0, entry - dot(x, -direction)) (0 for an empty scene).
double st_directional_entry(const st_scene *scene, const float direction[3]);

typedef struct st_incident {
    double to_light[3]; // unit direction from the point toward the light
    double dist;        // distance to the light (INFINITY: directional)
    double path;        // length of the light's path through the medium
    double E[3];        // irradiance on a surface facing the light, before the medium
} st_incident;

// What one light delivers at x: point I/d^2, spot I falloff/d^2, directional
// E. False (and *out zeroed) when nothing arrives (x at the light, outside the
// spot's cone). `entry` is st_directional_entry for directional lights.
bool st_light_incident(const st_light_desc *l, double entry, const double x[3], st_incident *out);

// Direct light on a Lambertian surface: rho/pi E max(cos, 0) e^(-sigma_t path).
static inline double st_direct_lambert(double rho, double E, double cos_theta, double path,
                                       double sigma_t) {
    return cos_theta > 0.0
               ? rho / ST_PI * E * cos_theta * (sigma_t > 0.0 ? exp(-sigma_t * path) : 1.0)
               : 0.0;
}

// ---- Phase functions (normalized: integral over the sphere = 1) ----------
double st_phase_isotropic(void);                // 1/(4 pi)
double st_phase_rayleigh(double cos_theta);     // 3/(16 pi) (1 + cos^2)
double st_phase_hg(double cos_theta, double g); // |g| clamped to 0.999
double st_phase_eval(st_phase_kind kind, double cos_theta, double g);

// The thesis listing A.11, kept to measure how wrong it is (not normalized):
// HG as (1 - g)^2 / (1 + g^2 - 2 g cos) -- squared (1 - g) instead of
// (1 - g^2), no 4 pi, no power 1.5 -- and Rayleigh as cos^2.
double st_phase_hg_thesis(double cos_theta, double g);
double st_phase_rayleigh_thesis(double cos_theta);

// ---- Integration of one march step ----------------------------------------
// ENERGY: Hillaire 2015, exact for a source constant over the step.
// THESIS: the thesis' Riemann sum as its listing A.12 marches it: the source
//   and the camera transmittance are taken at the step end nearer the camera
//   (constant source, sigma_t 0.5, length 10, 4 steps: 3.480).
// THESIS_FAR: the other Riemann sum, taken at the far end of each step
//   (same case: 0.997). The exact answer is 1.986524.
typedef enum {
    ST_INTEGRATOR_ENERGY = 0,
    ST_INTEGRATOR_THESIS,
    ST_INTEGRATOR_THESIS_FAR
} st_integrator;

bool st_integrator_parse(const char *name, st_integrator *out); // "energy", "thesis", "thesis_far"
const char *st_integrator_name(st_integrator it);

// A march from the camera outward: L the in-scattered radiance so far, T the
// transmittance from the camera to the start of the next step.
typedef struct st_march {
    double L, T;
} st_march;

static inline st_march st_march_begin(void) {
    return (st_march){0.0, 1.0};
}
// (1 - e^(-sigma_t dt)) / sigma_t, with the limit dt as sigma_t -> 0.
double st_step_transfer(double sigma_t, double dt);
// Adds one step of length dt with source S (radiance per metre).
void st_march_step(st_march *m, st_integrator it, double S, double sigma_t, double dt);
// A whole march of a constant source over [0, length] in `steps` steps.
double st_march_constant(st_integrator it, double S, double sigma_t, double length, int steps);

// ---- Single scattering from a point light along an unshadowed ray ---------
typedef struct st_inscatter_problem {
    double origin[3], dir[3]; // dir need not be normalized
    double length;            // s: the ray segment [0, s]
    double light[3];
    double intensity;        // I [W/sr]
    double sigma_s, sigma_t; // 1/m
    st_phase_kind phase;
    double g;
} st_inscatter_problem;

// e^(-sigma_t t) sigma_s phase I / d(t)^2 e^(-sigma_t d(t)) at ray distance t.
double st_inscatter_integrand(const st_inscatter_problem *p, double t);
// Brute force: composite Simpson with `steps` intervals (rounded up to even).
double st_inscatter_quadrature(const st_inscatter_problem *p, int steps);
// Zero extinction, isotropic: sigma_s I/(4 pi) (atan(b/h) - atan(a/h)) / h.
double st_inscatter_atan(double sigma_s, double intensity, double h, double a, double b);
// F(u, v) = integral_0^v e^(-u tan x) dx (adaptive Gauss-Kronrod, ~1e-12 rel).
double st_sun_F(double u, double v);
// Sun et al. 2005 for an isotropic medium, scaled by sigma_s/sigma_t. D the
// viewer-light distance, gamma the angle between the ray and the direction to
// the light, s the segment length. Near sin(gamma) = 0 the formula is 0/0 and
// the integral is evaluated by adaptive quadrature instead; a light on the
// segment itself gives +inf.
double st_inscatter_sun(double sigma_s, double sigma_t, double intensity, double D, double gamma,
                        double s);
// The same for a problem struct (phase must be isotropic).
double st_inscatter_sun_problem(const st_inscatter_problem *p);

// ---- Equi-angular quadrature of the unshadowed integral --------------------
// Kulla & Fajardo 2012: the ray point is parametrized by the angle theta it
// makes, seen from the light, with the ray's foot point (t = t_foot + h tan
// theta). dt / d^2 = dtheta / h, so the integrand becomes
// sigma_s phase I / h e^(-sigma_t (t + d)) dtheta: bounded and smooth, and a
// few Gauss-Legendre nodes integrate the 1/d^2 peak of a visible light.
// shaders/toth/equiangular.glsl mirrors this.
typedef struct st_equiangular {
    double h;      // light-ray distance (clamped to h_min)
    double a;      // ray start relative to the foot point (= -t_foot)
    double D;      // light distance from the ray start, sqrt(h^2 + a^2)
    double length; // Delta: the angle the segment [0, s] subtends at the light
} st_equiangular;

// The frame of ray p seen from its light; h below h_min is raised to h_min
// (the light then sits h_min off the ray: a ray through the light stays finite).
st_equiangular st_equiangular_frame(const st_inscatter_problem *p, double h_min);
// Ray distance t and light distance d of the point at angle delta in [0, Delta]
// from the ray start; the denominator D cos(theta) never vanishes.
void st_equiangular_point(const st_equiangular *e, double delta, double *t, double *d);
// How many of `panels` panels go before the foot point (at angle *foot from
// the ray start), in proportion to the angles; 0 when the segment does not
// pass the foot point or there is a single panel.
int st_equiangular_split(const st_equiangular *e, int panels, double *foot);
// The unshadowed single-scattering integral of p by Gauss-Legendre in theta:
// ceil(nodes / 4) panels of 4 nodes, split at the foot point.
double st_inscatter_equiangular(const st_inscatter_problem *p, int nodes, double h_min);

// ---- Adaptive quadrature ---------------------------------------------------
typedef double (*st_integrand)(double x, void *ctx);
// Adaptive Gauss-Kronrod 7/15 on [a, b] to max(abs_tol, rel_tol |I|).
double st_integrate(st_integrand f, void *ctx, double a, double b, double abs_tol, double rel_tol);

// ---- Form factors ----------------------------------------------------------
// From a differential area at p with unit normal n to a planar convex or
// concave polygon (Lambert's contour formula; only the part in front of p
// counts if the polygon is entirely in front).
double st_ff_point_polygon(const double p[3], const double n[3], const double (*v)[3], int count);
// A point under a coaxial disk of radius R at height h: R^2 / (R^2 + h^2).
double st_ff_point_disk(double R, double h);
// Closed forms (Hottel / Howell's catalogue): directly opposed parallel
// rectangles a x b at distance c; rectangles sharing an edge of length l at
// 90 degrees, from the one of width w to the one of height h.
double st_ff_parallel_rects(double a, double b, double c);
double st_ff_perpendicular_rects(double l, double w, double h);
// Numerically: from parallelogram A (corner ca, edges ua, va, front normal
// normalize(ua x va)) to parallelogram B, as the area average over A of the
// point-to-polygon form factor (nested adaptive quadrature, ~1e-9).
double st_ff_parallelograms(const double ca[3], const double ua[3], const double va[3],
                            const double cb[3], const double ub[3], const double vb[3]);

// The atlas gather's bounded kernel: a texel of area a at distance d is
// treated as a disk facing the receiver, so a/d^2 becomes pi a / (pi d^2 + a)
// (the disk's form factor times pi; exact for a coaxial disk).
double st_area_kernel(double a, double d2);

#ifdef __cplusplus
}
#endif
#endif
