// Direct light in the reference against rho/pi I cos/d^2 V evaluated at each
// pixel's hit point, found by an independent ray caster written here.
#include "ref_test_util.h"

typedef struct {
    double c[3], u[3], v[3], n[3]; // parallelogram, n = normalize(u x v)
    double albedo, emission;
    bool double_sided;
} tquad;

static tquad make(const double c[3], const double u[3], const double v[3], double albedo,
                  double emission) {
    tquad q = {
        {c[0], c[1], c[2]}, {u[0], u[1], u[2]}, {v[0], v[1], v[2]}, {0}, albedo, emission, false};
    q.n[0] = u[1] * v[2] - u[2] * v[1], q.n[1] = u[2] * v[0] - u[0] * v[2],
    q.n[2] = u[0] * v[1] - u[1] * v[0];
    double l = sqrt(q.n[0] * q.n[0] + q.n[1] * q.n[1] + q.n[2] * q.n[2]);
    for (int k = 0; k < 3; k++)
        q.n[k] /= l;
    return q;
}

static double dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Ray (o, d) against a parallelogram: distance or -1. *margin is how far
// inside the edges the hit lies, in parameter units (to skip ambiguous hits).
static double hit_quad(const tquad *q, const double o[3], const double d[3], double *margin) {
    double dn = dot(d, q->n);
    if (fabs(dn) < 1e-12) return -1;
    double oc[3] = {q->c[0] - o[0], q->c[1] - o[1], q->c[2] - o[2]};
    double t = dot(oc, q->n) / dn;
    if (t <= 1e-9) return -1;
    double p[3] = {o[0] + t * d[0] - q->c[0], o[1] + t * d[1] - q->c[1], o[2] + t * d[2] - q->c[2]};
    // Solve p = a u + b v in the plane (u, v orthogonal in these tests).
    double a = dot(p, q->u) / dot(q->u, q->u), b = dot(p, q->v) / dot(q->v, q->v);
    if (a < 0 || a > 1 || b < 0 || b > 1) return -1;
    if (margin) *margin = fmin(fmin(a, 1 - a), fmin(b, 1 - b));
    return t;
}

// Expected direct radiance of the pixel, or NAN where the answer is
// ambiguous at float precision (a silhouette or a shadow edge).
static double expected(const tquad *qs, int nq, const double light[3], double I, const double o[3],
                       const double d[3]) {
    int best = -1;
    double tb = INFINITY, margin = 1;
    for (int k = 0; k < nq; k++) {
        double m, t = hit_quad(&qs[k], o, d, &m);
        if (t > 0 && t < tb) tb = t, best = k, margin = m;
    }
    if (best < 0) return 0.0;
    if (margin < 1e-4) return NAN;
    const tquad *q = &qs[best];
    double p[3] = {o[0] + tb * d[0], o[1] + tb * d[1], o[2] + tb * d[2]};
    double n[3] = {q->n[0], q->n[1], q->n[2]};
    bool front = dot(d, n) < 0;
    if (!front && !q->double_sided) return 0.0;
    if (!front)
        for (int k = 0; k < 3; k++)
            n[k] = -n[k];
    double L[3] = {light[0] - p[0], light[1] - p[1], light[2] - p[2]};
    double d2 = dot(L, L), dl = sqrt(d2), ld[3] = {L[0] / dl, L[1] / dl, L[2] / dl};
    double cosv = dot(n, ld);
    double e = q->emission;
    if (cosv <= 0) return e;
    for (int k = 0; k < nq; k++) {
        if (k == best) continue;
        double m, t = hit_quad(&qs[k], p, ld, &m);
        if (t > 0 && t < dl) {
            if (m < 1e-4) return NAN;
            return e; // in shadow
        }
    }
    return e + q->albedo / ST_PI * I * cosv / d2;
}

static st_mesh *add_tquad(st_scene *s, const tquad *q) {
    st_mesh *m = add_quad(s, q->c, q->u, q->v, q->albedo, q->emission);
    m->double_sided = q->double_sided;
    return m;
}

// Renders the scene and compares every unambiguous pixel with `expected`.
static void compare(const char *name, st_scene *s, const tquad *qs, int nq, const double light[3],
                    double I) {
    st_ref_options o = {.spp = 1, .aov = ST_REF_DIRECT, .bounces = 0};
    st_image img;
    if (!render(s, &o, &img)) {
        CHECK(0, "%s: render failed", name);
        return;
    }
    const double cam[3] = {s->camera.position[0], s->camera.position[1], s->camera.position[2]};
    int checked = 0, lit = 0, dark = 0, bad = 0;
    double worst = 0;
    for (int j = 0; j < img.height; j++)
        for (int i = 0; i < img.width; i++) {
            double d[3];
            contract_ray(s, i, j, d);
            double want = expected(qs, nq, light, I, cam, d);
            const float *px = st_image_px(&img, i, j);
            if (px[3] != 0.0f) bad++; // direct light has no noise, so no standard error
            if (isnan(want)) continue;
            checked++;
            want > 0 ? lit++ : dark++;
            double err = fabs(px[0] - want) / fmax(want, 1e-3);
            if (err > worst) worst = err;
            if (err > 1e-4 || px[0] != px[1] || px[1] != px[2]) bad++;
        }
    fprintf(stderr, "  %s: %d pixels checked (%d lit, %d dark), worst rel error %.2e\n", name,
            checked, lit, dark, worst);
    CHECK(bad == 0, "%s: %d pixels differ from rho/pi I cos/d^2 V by more than 1e-4 (worst %.3g)",
          name, bad, worst);
    CHECK(checked > img.width * img.height / 2, "%s: only %d pixels checked", name, checked);
    st_image_free(&img);
}

static void plane_under_light(void) {
    const double cam[3] = {0, 2.5, 3}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0},
                 light[3] = {0.3, 1, -0.2};
    st_scene s;
    scene_init(&s, 64, 48, cam, tgt, up, 50, 100);
    add_light(&s, light, 2.0);
    tquad q[2] = {make((double[]){-5, 0, -5}, (double[]){0, 0, 10}, (double[]){10, 0, 0}, 0.6, 0)};
    add_tquad(&s, &q[0]);
    compare("plane", &s, q, 1, light, 2.0);
    // A blocker between the light and the plane: its own top is lit, its shadow is black.
    q[1] = make((double[]){-0.1, 0.5, -0.5}, (double[]){0, 0, 0.5}, (double[]){0.6, 0, 0}, 0.3, 0);
    add_tquad(&s, &q[1]);
    compare("plane with blocker", &s, q, 2, light, 2.0);
    st_scene_free(&s);
}

// Front side only unless double-sided, for reflection and emission alike;
// back faces are black but still occlude.
static void sides(void) {
    const double cam[3] = {0.2, -2, 0.1}, tgt[3] = {0, 0, 0}, up[3] = {0, 0, -1},
                 light[3] = {-0.4, -1, 0.3};
    for (int ds = 0; ds < 2; ds++) {
        st_scene s;
        scene_init(&s, 40, 40, cam, tgt, up, 60, 100);
        add_light(&s, light, 3.0);
        // Faces up (+y): the camera and the light below see its back.
        tquad q[2] = {
            make((double[]){-3, 0, -3}, (double[]){0, 0, 6}, (double[]){6, 0, 0}, 0.5, 0.0),
            // A small emitter below it, facing down toward the camera.
            make((double[]){-0.6, -0.5, -0.6}, (double[]){0.5, 0, 0}, (double[]){0, 0, 0.5}, 0.2,
                 0.25)};
        q[0].double_sided = q[1].double_sided = ds;
        add_tquad(&s, &q[0]);
        add_tquad(&s, &q[1]);
        compare(ds ? "double-sided" : "single-sided", &s, q, 2, light, 3.0);
        st_scene_free(&s);
    }
    // An emitter seen from its back: black unless double-sided.
    for (int ds = 0; ds < 2; ds++) {
        st_scene s;
        const double c2[3] = {0, 0, 3}, t2[3] = {0, 0, 0}, up2[3] = {0, 1, 0};
        scene_init(&s, 8, 8, c2, t2, up2, 30, 100);
        // normal u x v = -z: faces away from the camera at +z.
        st_mesh *m =
            add_quad(&s, (double[]){-1, -1, 0}, (double[]){0, 2, 0}, (double[]){2, 0, 0}, 0.5, 0.7);
        m->double_sided = ds;
        st_ref_options o = {.spp = 1, .aov = ST_REF_DIRECT};
        st_image img;
        if (render(&s, &o, &img)) {
            CHECK_REL(st_image_px(&img, 4, 4)[1], ds ? 0.7 : 0.0, 1e-6, 0);
            st_image_free(&img);
        }
        st_scene_free(&s);
    }
}

// With no medium and no bounce, combined equals direct; the reference's
// camera follows the contract (checked above through every hit point).
static void combined_equals_direct(void) {
    const double cam[3] = {0, 2.5, 3}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0},
                 light[3] = {0.3, 1, -0.2};
    st_scene s;
    scene_init(&s, 24, 24, cam, tgt, up, 50, 100);
    add_light(&s, light, 2.0);
    add_quad(&s, (double[]){-5, 0, -5}, (double[]){0, 0, 10}, (double[]){10, 0, 0}, 0.6, 0);
    st_ref_options od = {.spp = 1, .aov = ST_REF_DIRECT}, oc = {.spp = 4, .aov = ST_REF_COMBINED};
    st_image a, b;
    if (render(&s, &od, &a) && render(&s, &oc, &b)) {
        int diff = 0;
        for (size_t k = 0; k < (size_t)a.width * a.height * 6; k++)
            diff += a.data[k] != b.data[k];
        CHECK(diff == 0, "combined (no medium, no bounce) differs from direct in %d values", diff);
        st_image_free(&a);
        st_image_free(&b);
    }
    st_scene_free(&s);
}

// A plane in an absorbing medium (sigma_s = 0: no in-scatter, no noise):
// every pixel is rho/pi I cos/d^2 e^(-sigma_t d), d from the light, seen
// through e^(-sigma_t s), s from the camera (docs/physics.md).
static void plane_in_medium(void) {
    const double cam[3] = {0, 2.5, 3}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0},
                 light[3] = {0.3, 1, -0.2};
    const double I = 2.0, rho = 0.6, sigma_a = 0.35;
    const int W = 32, H = 24;
    st_scene s;
    scene_init(&s, W, H, cam, tgt, up, 50, 100);
    add_light(&s, light, I);
    add_quad(&s, (double[]){-5, 0, -5}, (double[]){0, 0, 10}, (double[]){10, 0, 0}, rho, 0);
    set_medium(&s, 0.0, sigma_a, ST_PHASE_ISOTROPIC, 0);
    st_ref_options o = {.spp = 2, .aov = ST_REF_COMBINED};
    st_image img;
    if (render(&s, &o, &img)) {
        double worst = 0, mean_t = 0;
        int n = 0;
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W; i++) {
                double d[3];
                contract_ray(&s, i, j, d);
                if (d[1] >= -1e-3) continue;
                double t = -cam[1] / d[1], p[3], l[3];
                for (int k = 0; k < 3; k++)
                    p[k] = cam[k] + t * d[k], l[k] = light[k] - p[k];
                if (fabs(p[0]) > 4.9 || fabs(p[2]) > 4.9) continue; // off the quad or at its edge
                double dl = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
                double want = st_direct_point(rho, I, l[1] / dl, dl, sigma_a) * exp(-sigma_a * t);
                worst = fmax(worst, fabs(st_image_px(&img, i, j)[0] - want) / want);
                mean_t += exp(-sigma_a * (t + dl)), n++;
            }
        printf("  plane in medium: worst relative error %.2e over %d pixels (mean transmittance "
               "%.3f)\n",
               worst, n, mean_t / n);
        CHECK(n > 300 && mean_t / n < 0.5, "the medium matters: %d pixels, mean transmittance %g",
              n, mean_t / n);
        CHECK(worst < 1e-5, "plane in medium: worst relative error %g", worst);
        st_image_free(&img);
    }
    st_scene_free(&s);
}

// Directional and spot lights (docs/physics.md): a sun in an absorbing medium
// over a plane with a square occluder 0.5 m above it -- pixels whose ray to
// the sun crosses the square are exactly 0, the others rho/pi E cos
// e^(-sigma_t path) seen through e^(-sigma_t s), path from the entry plane --
// and a spot's falloff, written out again here.
static void sun_and_spot(void) {
    const double cam[3] = {0, 2.5, 3}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    const double rho = 0.6, E = 2.0, sigma_a = 0.2,
                 spot_pos[3] = {0.25, 1.5, -0.25}; // exact in float
    const double sun[3] = {0.3 / 1.0630146, -1 / 1.0630146, 0.2 / 1.0630146};
    const int W = 48, H = 32;
    for (int type = 1; type <= 2; type++) {
        st_scene s;
        scene_init(&s, W, H, cam, tgt, up, 50, 100);
        add_quad(&s, (double[]){-5, 0, -5}, (double[]){0, 0, 10}, (double[]){10, 0, 0}, rho, 0);
        // The occluder: [-0.5, 0.5]^2 at y = 0.5, facing up (its back sees the plane).
        add_quad(&s, (double[]){-0.5, 0.5, -0.5}, (double[]){0, 0, 1}, (double[]){1, 0, 0}, 0.5, 0);
        st_light_desc l = {0};
        l.type = type == 1 ? ST_LIGHT_DIRECTIONAL : ST_LIGHT_SPOT;
        for (int k = 0; k < 3; k++)
            l.intensity[k] = (float)E,
            l.direction[k] = (float)(type == 1 ? sun[k] : (k == 1 ? -1 : 0)),
            l.position[k] = (float)spot_pos[k];
        l.inner_angle = 0.5f, l.outer_angle = 1.0f;
        st_err err = {0};
        CHECK(st_scene_add_light(&s, &l, &err), "add light");
        if (type == 1) set_medium(&s, 0.0, sigma_a, ST_PHASE_ISOTROPIC, 0);
        st_ref_options o = {.spp = 2, .aov = ST_REF_COMBINED};
        st_image img;
        if (!render(&s, &o, &img)) continue;
        double entry = -INFINITY; // corners of the scene's bounds
        for (int k = 0; k < 8; k++) {
            double c[3] = {k & 1 ? 5 : -5, k & 2 ? 0.5 : 0, k & 4 ? 5 : -5};
            entry = fmax(entry, -(c[0] * sun[0] + c[1] * sun[1] + c[2] * sun[2]));
        }
        double worst = 0;
        int lit = 0, shadow = 0, shadow_bad = 0;
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W; i++) {
                double d[3], p[3], l2[3];
                contract_ray(&s, i, j, d);
                if (d[1] >= -1e-3) continue;
                double t = -cam[1] / d[1];
                for (int k = 0; k < 3; k++)
                    p[k] = cam[k] + t * d[k];
                if (fabs(p[0]) > 4.9 || fabs(p[2]) > 4.9) continue;
                // Seen through the occluder, or near its outline from the camera: skip.
                double to_occ = (cam[1] - 0.5) / -d[1];
                double q[3] = {cam[0] + to_occ * d[0], 0.5, cam[2] + to_occ * d[2]};
                if (fabs(q[0]) < 0.55 && fabs(q[2]) < 0.55) continue;
                double want, cosv, f = 1, dist;
                if (type == 1) {
                    for (int k = 0; k < 3; k++)
                        l2[k] = -sun[k];
                    cosv = l2[1];
                    double path = entry - (p[0] * l2[0] + p[1] * l2[1] + p[2] * l2[2]);
                    want = rho / ST_PI * E * cosv * exp(-sigma_a * (path + t));
                    dist = 0.5 / l2[1];
                } else {
                    double v[3] = {spot_pos[0] - p[0], spot_pos[1] - p[1], spot_pos[2] - p[2]};
                    dist = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                    for (int k = 0; k < 3; k++)
                        l2[k] = v[k] / dist;
                    cosv = l2[1];
                    double a = (l2[1] - cos(1.0f)) / fmax(0.001, cos(0.5f) - cos(1.0f));
                    a = fmin(fmax(a, 0.0), 1.0), f = a * a;
                    want = rho / ST_PI * E * f * cosv / (dist * dist);
                    dist = 0.5 / l2[1];
                }
                // Where the shadow ray crosses y = 0.5.
                double c[3] = {p[0] + dist * l2[0], 0.5, p[2] + dist * l2[2]};
                double m = fmin(0.5 - fabs(c[0]), 0.5 - fabs(c[2]));
                if (fabs(m) < 0.02 || (f > 0 && f < 1e-3)) continue; // shadow or cone edge
                float v = st_image_px(&img, i, j)[0];
                if (m > 0 || f == 0) {
                    shadow++;
                    shadow_bad += v != 0;
                } else {
                    lit++;
                    worst = fmax(worst, fabs(v - want) / want);
                }
            }
        printf("  %s: worst relative error %.2e over %d lit pixels; %d dark pixels, %d not 0\n",
               type == 1 ? "sun in a medium" : "spot", worst, lit, shadow, shadow_bad);
        CHECK(lit > 300 && shadow > 20, "%s: %d lit, %d dark", type == 1 ? "sun" : "spot", lit,
              shadow);
        // The spot's falloff is steep near its outer cone: Embree's float hit
        // points (~1e-7 relative) become ~2e-5 there.
        CHECK(worst < (type == 1 ? 1e-5 : 1e-4) && shadow_bad == 0,
              "%s: worst %g, %d dark pixels lit", type == 1 ? "sun" : "spot", worst, shadow_bad);
        st_image_free(&img);
        st_scene_free(&s);
    }
}

// The scene's background: a camera ray that hits nothing sees its radiance
// at the far plane, dimmed like a surface there, e^(-sigma_t far / cos); it
// lights nothing (the plane below stays black without lights).
static void background(void) {
    const double cam[3] = {0, 1, 3}, tgt[3] = {0, 0.6, 0}, up[3] = {0, 1, 0}, far_z = 20;
    const double sigma_a = 0.05, B[3] = {0.2, 0.3, 0.6};
    const int W = 24, H = 16;
    st_scene s;
    scene_init(&s, W, H, cam, tgt, up, 50, far_z);
    add_quad(&s, (double[]){-5, 0, -5}, (double[]){0, 0, 10}, (double[]){10, 0, 0}, 0.5, 0);
    for (int c = 0; c < 3; c++)
        s.background[c] = (float)B[c];
    s.has_background = true;
    set_medium(&s, 0.0, sigma_a, ST_PHASE_ISOTROPIC, 0);
    st_ref_options o = {.spp = 1, .aov = ST_REF_COMBINED};
    st_image img;
    if (render(&s, &o, &img)) {
        double worst_sky = 0, worst_plane = 0;
        int n_sky = 0, n_plane = 0;
        double ax[3] = {tgt[0] - cam[0], tgt[1] - cam[1], tgt[2] - cam[2]};
        double al = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W; i++) {
                double d[3];
                contract_ray(&s, i, j, d);
                double cos_axis = (d[0] * ax[0] + d[1] * ax[1] + d[2] * ax[2]) / al;
                double t_far = far_z / cos_axis, y_far = cam[1] + t_far * d[1];
                const float *px = st_image_px(&img, i, j);
                if (d[1] > 1e-3 || y_far > 0.05) { // misses the plane within far
                    double T = exp(-sigma_a * t_far);
                    for (int c = 0; c < 3; c++)
                        worst_sky = fmax(worst_sky, fabs(px[c] - B[c] * T) / (B[c] * T));
                    n_sky++;
                } else if (fabs(cam[0] - cam[1] / d[1] * d[0]) < 4.9 &&
                           fabs(cam[2] - cam[1] / d[1] * d[2]) < 4.9) { // on the quad
                    for (int c = 0; c < 3; c++)
                        worst_plane = fmax(worst_plane, fabs(px[c]));
                    n_plane++;
                }
            }
        printf(
            "  background: %d sky pixels, worst relative error %.2e; %d plane pixels, max %.2e\n",
            n_sky, worst_sky, n_plane, worst_plane);
        CHECK(n_sky > 50 && n_plane > 50, "background: %d sky, %d plane pixels", n_sky, n_plane);
        CHECK(worst_sky < 1e-5, "background seen through the medium: worst relative error %g",
              worst_sky);
        CHECK(worst_plane == 0, "the background lights nothing: %g", worst_plane);
        st_image_free(&img);
    }
    st_scene_free(&s);
}

// A closed room of six 5 cm wall boxes with the camera inside on its axis,
// at an even image size: pixel centres on the image diagonals land exactly
// on the edges where the floor and ceiling slabs meet the side walls. There
// the nearest hit is a tie between the visible faces and the hidden faces
// of the boxes in contact, and the tie must go to a side that reflects:
// with one bounce no point seen inside a closed lit room is black.
static void seams(void) {
    const double cam[3] = {0, 1, 0.9}, tgt[3] = {0, 1, 0}, up[3] = {0, 1, 0};
    const float walls[6][2][3] = {{{-1.05f, -0.05f, -1.05f}, {1.05f, 0, 1.05f}},
                                  {{-1.05f, 2, -1.05f}, {1.05f, 2.05f, 1.05f}},
                                  {{-1.05f, 0, -1.05f}, {1.05f, 2, -1}},
                                  {{-1.05f, 0, 1}, {1.05f, 2, 1.05f}},
                                  {{-1.05f, 0, -1}, {-1, 2, 1}},
                                  {{1, 0, -1}, {1.05f, 2, 1}}};
    st_scene s;
    scene_init(&s, 64, 64, cam, tgt, up, 90, 100);
    add_light(&s, (double[]){0.2, 1.7, -0.3}, 10.0);
    st_err err = {0};
    for (int k = 0; k < 6; k++) {
        st_mesh m;
        st_mesh_box(&m, walls[k][0], walls[k][1], false);
        v3(m.albedo, 0.75, 0.75, 0.75);
        CHECK(m.positions && st_scene_add_mesh(&s, &m, &err), "wall box %d: %s", k, err.msg);
    }
    // 64 samples: a point exactly on a seam can sit inside the neighbouring
    // box by float rounding, which traps some of its shadow and bounce rays
    // (a few samples, not the pixel); a back face is black at any count.
    st_ref_options o = {.spp = 64, .bounces = 1, .aov = ST_REF_COMBINED};
    st_image img;
    if (render(&s, &o, &img)) {
        int black = 0;
        for (int j = 0; j < img.height; j++)
            for (int i = 0; i < img.width; i++) {
                const float *px = st_image_px(&img, i, j);
                black += px[0] <= 0.0f && px[1] <= 0.0f && px[2] <= 0.0f;
            }
        printf("seams: %d of %d pixels black\n", black, img.width * img.height);
        CHECK(black == 0, "%d pixels inside the closed room are black", black);
        st_image_free(&img);
    }
    st_scene_free(&s);
}

int main(void) {
    seams();
    plane_under_light();
    plane_in_medium();
    sun_and_spot();
    sides();
    combined_equals_direct();
    background();
    return st_test_summary("reference_direct");
}
