// Surface light in the reference: direct light from point lights with exact
// shadows, and the diffuse bounce estimators.
//
// Indirect light at a receiver x with albedo rho, one bounce:
//   L1(x) = rho/pi integral_A L0(y) V(x,y) cos+(theta_x) cos+(theta_y) / d^2 e^(-sigma_t d) dA(y)
// (e^(-sigma_t d) = 1 without a medium; direct light carries it too).
// with L0(y) = emission + direct (+ the previous bounce for K > 1, computed
// the same way, recursively: one path per sample).
//   visibility on:  cosine-weighted directions from x (pdf cos/pi), traced to
//                   the first surface y: estimate rho L0(y). Bounded.
//   visibility off: the same integral with V = 1 (what atlas_gi computes with
//                   visibility=off). Pure area sampling (y uniform over all
//                   triangles, rho/pi A L0 cos cos / d^2) has unbounded
//                   weights near concave edges, so its noise estimate is
//                   unreliable; instead one-sample MIS (balance heuristic,
//                   Veach 1997) of that area sampling and cosine-weighted
//                   directions that count every surface the ray crosses (V = 1
//                   means all of them face x's hemisphere unoccluded). Either
//                   technique scores f / (p_dir/2 + p_area/2), in area measure
//                   rho L0 cos cos / (cos cos + pi d^2 / A) * 2: bounded by
//                   2 rho L0. A ray crossing k facing surfaces scores one of
//                   them picked uniformly, times k. Same expectation as the
//                   area estimator, far less noise.
//   thesis:         area samples weighed as if uniform in solid angle (Merz
//                   2010 eq. 9): rho/pi 2 pi L0(y) cos+(theta_x) for mutually
//                   facing points, no sender cosine, no 1/d^2, no visibility.
//                   Samples over the whole scene count in N, like atlas texels
//                   that face away. Two unit squares sharing an edge: 2.82x
//                   the true value.
#include "ref.h"
#include <math.h>
#include <string.h>
#include "st_vec3.h"

void st_ref_direct(const st_ref_geometry *g, const st_ref_surface *s, st_ref_rng *rng,
                   double out[3]) {
    out[0] = out[1] = out[2] = 0.0;
    if (!s->hit || !s->lit_side) return; // back faces are black but occlude
    for (int c = 0; c < 3; c++)
        out[c] = s->mesh->emission[c];
    const st_scene *sc = g->desc;
    double from[3];
    st_ref_offset(g, s, from);
    for (int i = 0; i < sc->num_lights; i++) {
        st_incident in;
        if (!st_light_incident(&sc->lights[i], g->light_entry[i], s->p, &in)) continue;
        const double cos_n = st_dot3(s->n, in.to_light);
        // A light behind the geometric surface is blocked by the surface itself.
        if (cos_n <= 0.0 || st_dot3(s->ng, in.to_light) <= 0.0) continue;
        if (in.E[0] == 0.0 && in.E[1] == 0.0 && in.E[2] == 0.0) continue;
        if (!st_ref_light_visible(g, from, s->p, &in)) continue;
        // A varying density: the light path's transmittance by ratio tracking.
        double T[3] = {1.0, 1.0, 1.0}, path = in.path;
        if (st_density_varies(&sc->density))
            st_ref_transmittance(g, s->p, in.to_light, 0.0, in.path, rng, T), path = 0.0;
        for (int c = 0; c < 3; c++)
            out[c] +=
                st_direct_lambert(s->mesh->albedo[c], in.E[c] * T[c], cos_n, path, g->sigma_t[c]);
    }
}

// Outgoing radiance of y toward its viewer with `bounces` bounces of indirect.
static void outgoing(const st_ref_geometry *g, const st_ref_options *o, const st_ref_surface *y,
                     int bounces, st_ref_rng *rng, double out[3]) {
    st_ref_direct(g, y, rng, out);
    if (bounces <= 0 || !y->hit || !y->lit_side) return;
    double ind[3];
    st_ref_indirect(g, o, y, bounces, rng, ind);
    for (int c = 0; c < 3; c++)
        out[c] += ind[c];
}

// Cosine-weighted direction around unit n (Malley), with the branchless
// orthonormal basis of Duff et al. 2017.
static void cosine_direction(const double n[3], st_ref_rng *rng, double out[3]) {
    double u1 = st_ref_rng_uniform(rng), u2 = st_ref_rng_uniform(rng);
    double r = sqrt(u1), phi = 2.0 * ST_PI * u2;
    double x = r * cos(phi), y = r * sin(phi), z = sqrt(fmax(0.0, 1.0 - u1));
    double sign = copysign(1.0, n[2]);
    double a = -1.0 / (sign + n[2]), b = n[0] * n[1] * a;
    double t[3] = {1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]};
    double bt[3] = {b, sign + n[1] * n[1] * a, -n[1]};
    for (int k = 0; k < 3; k++)
        out[k] = x * t[k] + y * bt[k] + z * n[k];
}

static void indirect_traced(const st_ref_geometry *g, const st_ref_options *o,
                            const st_ref_surface *x, int bounces, st_ref_rng *rng, double out[3]) {
    double dir[3], from[3];
    cosine_direction(x->n, rng, dir);
    if (st_dot3(dir, x->ng) <= 0.0) return; // below the geometric surface (smooth normals)
    st_ref_offset(g, x, from);
    st_ref_surface y = st_ref_intersect(g, from, dir, 0.0, INFINITY);
    if (!y.hit || !y.lit_side) return;
    double L[3], T[3];
    outgoing(g, o, &y, bounces - 1, rng, L);
    st_ref_transmittance(g, from, dir, 0.0, y.t, rng, T); // dir is unit: t is the distance
    for (int c = 0; c < 3; c++)
        out[c] = x->mesh->albedo[c] * L[c] * T[c];
}

// The MIS score of the unoccluded bounce for y seen from x (see the top of
// the file). The direction technique's density turns into area measure with
// the geometric cosine at y; the integrand uses the shading cosines.
static void mis_score(const st_ref_geometry *g, const st_ref_options *o, const st_ref_surface *x,
                      const st_ref_surface *y, int bounces, double scale, st_ref_rng *rng,
                      double out[3]) {
    if (!y->hit || !y->lit_side) return;
    double w[3] = {y->p[0] - x->p[0], y->p[1] - x->p[1], y->p[2] - x->p[2]};
    double d2 = st_dot3(w, w);
    if (!(d2 > 0.0)) return;
    double d = sqrt(d2);
    double cos_x = st_dot3(x->n, w) / d, cos_y = -st_dot3(y->n, w) / d,
           cos_yg = -st_dot3(y->ng, w) / d;
    if (cos_x <= 0.0 || cos_y <= 0.0 || cos_yg <= 0.0) return;
    double L[3], T[3], u[3] = {w[0] / d, w[1] / d, w[2] / d};
    outgoing(g, o, y, bounces - 1, rng, L);
    st_ref_transmittance(g, x->p, u, 0.0, d, rng, T);
    double k = scale * 2.0 * cos_x * cos_y / (cos_x * cos_yg + ST_PI * d2 / g->total_area);
    for (int c = 0; c < 3; c++)
        out[c] = x->mesh->albedo[c] * k * L[c] * T[c];
}

enum { MAX_CROSSINGS = 64 }; // surfaces counted along one unoccluded ray

static void indirect_unoccluded(const st_ref_geometry *g, const st_ref_options *o,
                                const st_ref_surface *x, int bounces, st_ref_rng *rng,
                                double out[3]) {
    if (st_ref_rng_uniform(rng) < 0.5) {
        st_ref_surface y = st_ref_sample_area(g, rng, x->p);
        mis_score(g, o, x, &y, bounces, 1.0, rng, out);
        return;
    }
    double dir[3], from[3];
    cosine_direction(x->n, rng, dir);
    if (st_dot3(dir, x->ng) <= 0.0) return;
    st_ref_offset(g, x, from);
    st_ref_surface hits[MAX_CROSSINGS];
    int n = st_ref_intersect_all(g, from, dir, 0.0, INFINITY, hits, MAX_CROSSINGS), k = 0;
    for (int i = 0; i < n; i++) // keep the surfaces that face x
        if (hits[i].lit_side) hits[k++] = hits[i];
    if (k == 0) return;
    int pick = (int)(st_ref_rng_uniform(rng) * k);
    mis_score(g, o, x, &hits[pick < k ? pick : k - 1], bounces, (double)k, rng, out);
}

// The thesis estimator (see the top of the file).
static void indirect_thesis(const st_ref_geometry *g, const st_ref_options *o,
                            const st_ref_surface *x, int bounces, st_ref_rng *rng, double out[3]) {
    st_ref_surface y = st_ref_sample_area(g, rng, x->p);
    if (!y.hit || !y.lit_side) return;
    double w[3] = {y.p[0] - x->p[0], y.p[1] - x->p[1], y.p[2] - x->p[2]};
    double d = sqrt(st_dot3(w, w));
    if (!(d > 0.0)) return;
    double cos_x = st_dot3(x->n, w) / d, cos_y = -st_dot3(y.n, w) / d;
    if (cos_x <= 0.0 || cos_y <= 0.0) return; // "facing each other"
    double L[3], T[3], u[3] = {w[0] / d, w[1] / d, w[2] / d};
    outgoing(g, o, &y, bounces - 1, rng, L);
    st_ref_transmittance(g, x->p, u, 0.0, d, rng, T);
    for (int c = 0; c < 3; c++)
        out[c] = x->mesh->albedo[c] / ST_PI * 2.0 * ST_PI * cos_x * L[c] * T[c];
}

void st_ref_indirect(const st_ref_geometry *g, const st_ref_options *o, const st_ref_surface *s,
                     int bounces, st_ref_rng *rng, double out[3]) {
    out[0] = out[1] = out[2] = 0.0;
    if (bounces <= 0 || !s->hit || !s->lit_side) return;
    if (o->estimator == ST_REF_EST_THESIS)
        indirect_thesis(g, o, s, bounces, rng, out);
    else if (o->no_visibility)
        indirect_unoccluded(g, o, s, bounces, rng, out);
    else
        indirect_traced(g, o, s, bounces, rng, out);
}
