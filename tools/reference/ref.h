// strahl reference: the CPU renderer (Embree 3) that computes docs/physics.md's
// model with exact visibility and many samples. Internal to the tools.
//
// Model, per pixel: with the point filter one view ray through the pixel
// centre; with the box filter (the command's default) each sample's view ray
// through its own point, stratified uniformly over the pixel's square, so
// the pixel is the mean radiance over it. Per view ray:
//   direct    emission (front side) + sum over point lights of
//             rho/pi I max(cos, 0)/d^2 V, V from an exact shadow ray.
//   indirect  `bounces` diffuse bounces of L0 = emission + direct (+ the
//             previous bounce), see ref_shade.c for the estimators.
//   inscatter single scattering in the homogeneous medium, exact visibility,
//             see ref_medium.c.
//   combined  (direct + indirect) e^(-sigma_t s) + inscatter.
// A medium of varying density (medium.density) scales sigma_s and sigma_a by
// d(x) and estimates each e^(-sigma_t d) by ratio tracking (ref_medium.c).
// With a medium every light path is attenuated (docs/physics.md): light ->
// surface (direct), light -> scattering point (in-scatter) and sender ->
// receiver (each bounce) by e^(-sigma_t d); the view ray by e^(-sigma_t s).
#ifndef ST_REF_H
#define ST_REF_H
#include "st_base.h"
#include "st_image.h"
#include "st_physics.h"
#include "st_scene.h"
#include <embree3/rtcore.h>

typedef enum { ST_REF_COMBINED = 0, ST_REF_DIRECT, ST_REF_INDIRECT, ST_REF_INSCATTER } st_ref_aov;
typedef enum { ST_REF_EST_AREA = 0, ST_REF_EST_THESIS } st_ref_estimator;
// How a pixel's samples draw their random numbers (ref_render.c): Owen-
// scrambled Sobol points in independent batches (the default), or
// independent PCG32 numbers with the box filter's stratified grid.
typedef enum { ST_REF_SAMPLER_SOBOL = 0, ST_REF_SAMPLER_INDEPENDENT } st_ref_sampler;

typedef struct st_ref_options {
    int spp; // samples per pixel (>= 1; 0 means 1)
    st_ref_aov aov;
    uint64_t seed;
    int bounces;        // diffuse bounces (0: no indirect light)
    bool no_visibility; // bounce without the sender-receiver visibility test
    st_ref_estimator estimator;
    int march_steps;        // strata per view ray for in-scattering (0: 256)
    int threads;            // 0: all online cores
    st_pixel_filter filter; // point (0): pixel centres; box: stratified over the pixel
    st_ref_sampler sampler;
    // Called from the calling thread about every 10 ms with the rows done
    // (and once at the end with all of them); NULL: none.
    void (*progress)(void *user, int rows_done, int rows);
    void *progress_user;
} st_ref_options;

// World-space triangles of all meshes in one Embree scene.
typedef struct st_ref_geometry {
    RTCDevice device;
    RTCScene scene;
    const st_scene *desc;
    int num_meshes;
    double **pos; // per mesh: 3 doubles per vertex, world space
    double **nrm; // per mesh: 3 doubles per vertex, world space, unit
    double **ng;  // per mesh: unit geometric normal per triangle (CCW front)
    // Area sampling over every triangle of the scene.
    double *cdf;        // cumulative area, one entry per triangle (global order)
    int *tri_mesh;      // global triangle -> mesh
    uint32_t *tri_prim; // global triangle -> triangle in its mesh
    uint64_t num_tris;
    double total_area;
    double eps;               // scene-scale tolerance (ties, back-side exits, light on a surface)
    double sigma_t[3];        // the medium's extinction, 0 without one (light paths)
    double *light_entry;      // per light: st_directional_entry (directional lights)
    double center[3], radius; // a sphere around the scene's bounds (shadow rays to infinity)
} st_ref_geometry;

// A surface point as a renderer sees it from one side.
typedef struct st_ref_surface {
    bool hit;      // false: the ray left the scene
    bool lit_side; // the visible side reflects and emits (front, or double-sided)
    double t;      // ray distance
    double p[3];   // position
    double n[3];   // unit shading normal, turned toward the side seen
    double ng[3];  // unit geometric normal, turned toward the side seen
    const st_mesh *mesh;
    int geom; // mesh index (the Embree geometry) and triangle of the hit
    uint32_t prim;
} st_ref_surface;

// PCG32 (O'Neill), one stream per pixel, seeded from (seed, pixel). After
// st_ref_rng_start_sample, st_ref_rng_uniform returns the sample's next
// dimension of an Owen-scrambled Sobol sequence instead (ref_rng.c).
typedef struct st_ref_rng {
    uint64_t state, inc;
    uint64_t key;        // scrambles of the sample's batch (its pixel, seed and batch)
    uint32_t index, n;   // the sample's index in its batch, the batch's size
    uint32_t dim;        // the next dimension
    uint32_t pair_index; // the current dimension pair's shuffled index
    uint64_t scrambles;  // and its two Owen scramble seeds (32 bits each)
    bool ld;             // low-discrepancy: false = plain PCG32
} st_ref_rng;
void st_ref_rng_seed(st_ref_rng *r, uint64_t seed, uint64_t stream);
uint32_t st_ref_rng_u32(st_ref_rng *r);
double st_ref_rng_uniform(st_ref_rng *r); // [0, 1)
// Sample `index` of a batch of n, scrambled by `key`: from now on each
// st_ref_rng_uniform is the next dimension of that point.
void st_ref_rng_start_sample(st_ref_rng *r, uint64_t key, uint32_t index, uint32_t n);
uint64_t st_ref_rng_hash(uint64_t a, uint64_t b);

bool st_ref_geometry_build(st_ref_geometry *g, const st_scene *scene, st_err *err);
void st_ref_geometry_free(st_ref_geometry *g);
// Closest hit along o + t d for t in (tmin, tmax); d need not be unit.
st_ref_surface st_ref_intersect(const st_ref_geometry *g, const double o[3], const double d[3],
                                double tmin, double tmax);
// Every surface along the ray (unit d), nearest first, at most `max`.
int st_ref_intersect_all(const st_ref_geometry *g, const double o[3], const double d[3],
                         double tmin, double tmax, st_ref_surface *out, int max);
// Whether the segment from surface-offset point `from` to `to` is blocked.
bool st_ref_occluded(const st_ref_geometry *g, const double from[3], const double to[3]);
// Whether light `in` (st_light_incident at `at`) reaches `from` (at, or at
// moved off its surface) unblocked: the shadow ray aims at the light's
// position; a directional light's runs until it has left the scene's bounds.
bool st_ref_light_visible(const st_ref_geometry *g, const double from[3], const double at[3],
                          const st_incident *in);
// The origin of a secondary ray (shadow or bounce) leaving surface s: s->p
// moved off its triangle along the side seen by a few float ulps of the
// triangle's coordinates (ref_geometry.c).
void st_ref_offset(const st_ref_geometry *g, const st_ref_surface *s, double out[3]);
// A point uniform over the scene's area, seen from `viewer` (its side chosen).
st_ref_surface st_ref_sample_area(const st_ref_geometry *g, st_ref_rng *rng,
                                  const double viewer[3]);

// Surface terms (ref_shade.c). Radiances are RGB.
// rng: for the light paths' transmittance in a medium of varying density
// (NULL is fine otherwise).
void st_ref_direct(const st_ref_geometry *g, const st_ref_surface *s, st_ref_rng *rng,
                   double out[3]);
void st_ref_indirect(const st_ref_geometry *g, const st_ref_options *o, const st_ref_surface *s,
                     int bounces, st_ref_rng *rng, double out[3]);

// Transmittance along o + t w (w unit) for t in [t0, t1] (ref_medium.c):
// e^(-sigma_t (t1 - t0)) in a homogeneous medium (1 without one), a ratio
// tracking estimate when the density varies (rng then must not be NULL).
// Refuses (ST_ERR_INPUT) a medium whose ratio tracking would need more than
// ST_REF_MAX_COLLISIONS tentative collisions on one ray (a VDB grid with a
// huge sigma_t: the tracking would never finish). Height fog needs no
// check: its pieces keep the collisions per ray bounded (ref_medium.c).
#define ST_REF_MAX_COLLISIONS 1e6
bool st_ref_medium_check(const st_scene *scene, st_err *err);
void st_ref_transmittance(const st_ref_geometry *g, const double o[3], const double w[3], double t0,
                          double t1, st_ref_rng *rng, double out[3]);

// In-scattering along the view ray [0, s] (ref_medium.c).
void st_ref_inscatter(const st_ref_geometry *g, const st_ref_options *o, const double origin[3],
                      const double dir[3], double s, st_ref_rng *rng, double out[3]);

// Renders the scene into a 6-channel image: R, G, B and the standard error of
// each pixel's mean (stderr.R/G/B). Deterministic for a given seed and
// independent of the thread count.
bool st_ref_render(const st_scene *scene, const st_ref_options *o, st_image *out, st_err *err);

// The image's estimated relative error: sqrt(mean stderr^2) / mean |value|
// over R, G, B (compare's debiased NRMSE against its own expectation).
double st_ref_relative_error(const st_image *img);
// Renders passes (the first with o's spp and seed, the next with seeds
// derived from it, merged like `strahl merge`) until the relative error is at
// most `target` or max_spp samples are reached (ref_target.c); *spp_out and
// *reached: what was reached.
bool st_ref_render_target(const st_scene *scene, const st_ref_options *o, double target,
                          long max_spp, st_image *out, long *spp_out, double *reached, st_err *err);

#endif
