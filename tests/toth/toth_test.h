// Shared helpers of the toth tests: the test room (a closed box seen from
// inside, so every view ray ends on a wall at a known distance), rendering
// with toth parameters, and per-pixel oracles from framework/st_physics.h.
#ifndef TOTH_TEST_H
#define TOTH_TEST_H
#include "st_test_render.h" // first: it defines _GNU_SOURCE
#include "st_physics.h"

// The room: box [-2,2] x [0,3] x [-2,2], walls facing inward.
static const double ROOM_MIN[3] = {-2, 0, -2}, ROOM_MAX[3] = {2, 3, 2};
static const double ROOM_CAM[3] = {0, 1.2, 1.5}, ROOM_TGT[3] = {0, 1.0, -2}, ROOM_UP[3] = {0, 1, 0};
static const double ROOM_FOV = 60;

// Distance from a point inside an axis-aligned box to where the ray leaves it.
static inline double toth_box_exit(const double o[3], const double d[3], const double mn[3],
                                   const double mx[3]) {
    double t = 1e30;
    for (int k = 0; k < 3; k++) {
        if (d[k] > 1e-15) t = fmin(t, (mx[k] - o[k]) / d[k]);
        if (d[k] < -1e-15) t = fmin(t, (mn[k] - o[k]) / d[k]);
    }
    return t;
}

// Writes the room scene with n point lights. medium: the JSON object's body
// (without braces) or NULL; toth_params: the body of toth's params object.
static inline void toth_write_room_n(const char *path, int size, int n, const double (*light)[3],
                                     const double (*I)[3], double albedo, const char *medium,
                                     const char *toth_params) {
    char json[4096], med[512] = "", lights[1024] = "";
    if (medium) snprintf(med, sizeof med, " \"medium\": {%s},\n", medium);
    for (int k = 0; k < n; k++) {
        size_t l = strlen(lights);
        snprintf(lights + l, sizeof lights - l,
                 "%s{\"type\": \"point\", \"position\": [%.17g, %.17g, %.17g], \"intensity\": [%g, "
                 "%g, %g]}",
                 k ? ", " : "", light[k][0], light[k][1], light[k][2], I[k][0], I[k][1], I[k][2]);
    }
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": %d, \"height\": %d},\n"
        " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, 0],"
        " \"fov_y\": %g, \"near\": 0.05, \"far\": 100},\n"
        " \"lights\": [%s],\n"
        " \"geometry\": [{\"box\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}, \"inward\": "
        "true,"
        " \"albedo\": [%g, %g, %g]}],\n"
        "%s"
        " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}},"
        " {\"name\": \"toth\", \"params\": {%s}}]}\n",
        size, size, ROOM_CAM[0], ROOM_CAM[1], ROOM_CAM[2], ROOM_TGT[0], ROOM_TGT[1], ROOM_TGT[2],
        ROOM_FOV, lights, ROOM_MIN[0], ROOM_MIN[1], ROOM_MIN[2], ROOM_MAX[0], ROOM_MAX[1],
        ROOM_MAX[2], albedo, albedo, albedo, med, toth_params ? toth_params : "");
    st_test_write(path, json);
}

static inline void toth_write_room(const char *path, int size, const double light[3],
                                   const double I[3], double albedo, const char *medium,
                                   const char *toth_params) {
    const double(*l)[3] = (const double(*)[3])light, (*i)[3] = (const double(*)[3])I;
    toth_write_room_n(path, size, 1, l, i, albedo, medium, toth_params);
}

// Renders and reads; returns 1 on success (the render's failure is a CHECK).
static inline int toth_render(const char *scene, const char *out, const char *extra,
                              st_image *img) {
    int rc = st_test_render(scene, out, extra);
    CHECK(rc == 0, "render %s %s: exit %d", scene, extra ? extra : "", rc);
    if (rc != 0 || !st_test_read(out, img)) return 0;
    CHECK(st_test_all_finite(img), "%s: every pixel finite", out);
    return 1;
}

// The unshadowed single-scattering problem of room pixel (i, j), channel c.
static inline st_inscatter_problem toth_room_problem(const st_test_cam *cam, int i, int j,
                                                     const double light[3], double I,
                                                     double sigma_s, double sigma_t,
                                                     st_phase_kind phase, double g) {
    st_inscatter_problem p;
    double d[3];
    st_test_ray(cam, i, j, d);
    for (int k = 0; k < 3; k++) {
        p.origin[k] = cam->pos[k];
        p.dir[k] = d[k];
        p.light[k] = light[k];
    }
    p.length = toth_box_exit(cam->pos, d, ROOM_MIN, ROOM_MAX);
    p.intensity = I;
    p.sigma_s = sigma_s;
    p.sigma_t = sigma_t;
    p.phase = phase;
    p.g = g;
    return p;
}

// Zero extinction, isotropic: the atan closed form of docs/physics.md.
static inline double toth_atan_oracle(const st_inscatter_problem *p) {
    double dl = sqrt(p->dir[0] * p->dir[0] + p->dir[1] * p->dir[1] + p->dir[2] * p->dir[2]);
    double rel[3] = {p->light[0] - p->origin[0], p->light[1] - p->origin[1],
                     p->light[2] - p->origin[2]};
    double foot = (rel[0] * p->dir[0] + rel[1] * p->dir[1] + rel[2] * p->dir[2]) / dl;
    double h2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2] - foot * foot;
    double h = sqrt(fmax(h2, 0.0));
    return st_inscatter_atan(p->sigma_s, p->intensity, h, -foot, p->length - foot);
}

static inline double toth_integrand_cb(double t, void *ctx) {
    return st_inscatter_integrand(ctx, t);
}

// Any phase function and extinction: adaptive Gauss-Kronrod to 1e-10.
static inline double toth_quad_oracle(const st_inscatter_problem *p) {
    return st_integrate(toth_integrand_cb, (void *)p, 0.0, p->length, 1e-300, 1e-10);
}

// Lit interval [t0, t1] of the view ray o + t d (0 <= t <= s) below a slab
// y in [y0, y1] with a square opening |x|, |z| <= hole: the segment to the
// light passes the opening at both slab faces. Eight half-spaces
// s (L_k + (x_k - L_k)(Y - L_y)/(x_y - L_y)) <= hole for k in {x, z},
// s = +-1, Y in {y0, y1}; times (L_y - x_y) > 0 each is linear in x:
// s (L_y - Y) x_k + (hole - s L_k) x_y + (s L_k Y - hole L_y) <= 0.
static inline int toth_lit_interval(const double light[3], double y0, double y1, const double o[3],
                                    const double d[3], double s, double hole, double *t0,
                                    double *t1) {
    double lo = 0, hi = s;
    const double Ys[2] = {y0, y1};
    for (int y = 0; y < 2; y++)
        for (int k = 0; k < 3; k += 2)
            for (int sg = -1; sg <= 1; sg += 2) {
                double a[3] = {0, hole - sg * light[k], 0};
                a[k] = sg * (light[1] - Ys[y]);
                double b = -(sg * light[k] * Ys[y] - hole * light[1]);
                double ad = a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
                double ao = a[0] * o[0] + a[1] * o[1] + a[2] * o[2];
                if (fabs(ad) < 1e-15) {
                    if (ao > b) return 0;
                    continue;
                }
                double t = (b - ao) / ad;
                if (ad > 0)
                    hi = fmin(hi, t);
                else
                    lo = fmax(lo, t);
            }
    *t0 = lo, *t1 = hi;
    return hi > lo;
}

#endif
