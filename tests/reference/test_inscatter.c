// In-scattering in the reference against the closed forms: zero extinction
// (atan form), Sun et al. 2005 with extinction, brute-force quadrature for
// Rayleigh and HG, and exact shadowing by an occluder.
#include "ref_test_util.h"

static const double cam[3] = {0, 0, 0}, tgt[3] = {0, 0, -1}, up[3] = {0, 1, 0};
static const double light[3] = {0.4, 1.5, -3.0};
static const double I = 4.0, far_z = 20.0;

// The ray length of pixel (i, j): to the far plane (view depth far_z).
static double far_length(const st_scene *s, const double d[3]) {
    (void)s;
    return far_z / -d[2]; // the view axis is -z
}

static void check_image(const char *name, const st_scene *s, const st_image *img, int kind) {
    int bad = 0, n = 0, noisy = 0;
    double worst = 0, z2 = 0;
    for (int j = 0; j < img->height; j++)
        for (int i = 0; i < img->width; i++) {
            double d[3];
            contract_ray(s, i, j, d);
            double len = far_length(s, d);
            const st_medium_desc *m = &s->medium;
            double ss = m->sigma_s[0], st = (double)m->sigma_s[0] + m->sigma_a[0];
            double want;
            double to_l[3] = {light[0] - cam[0], light[1] - cam[1], light[2] - cam[2]};
            double D = sqrt(to_l[0] * to_l[0] + to_l[1] * to_l[1] + to_l[2] * to_l[2]);
            if (kind == 0) { // zero extinction: the atan form with h and a, b from the foot point
                double foot = (to_l[0] * d[0] + to_l[1] * d[1] + to_l[2] * d[2]);
                double h = sqrt(fmax(D * D - foot * foot, 0));
                want = st_inscatter_atan(ss, I, h, -foot, len - foot);
            } else if (kind == 1) {
                double c = (to_l[0] * d[0] + to_l[1] * d[1] + to_l[2] * d[2]) / D;
                want = st_inscatter_sun(ss, st, I, D, acos(c), len);
            } else {
                st_inscatter_problem p = {{cam[0], cam[1], cam[2]},
                                          {d[0], d[1], d[2]},
                                          len,
                                          {light[0], light[1], light[2]},
                                          I,
                                          ss,
                                          st,
                                          m->phase,
                                          m->g};
                want = st_inscatter_quadrature(&p, 100000);
            }
            const float *px = st_image_px(img, i, j);
            double err = fabs(px[0] - want) / want;
            worst = fmax(worst, err);
            if (px[3] > 1e-6 * want) {
                z2 += (px[0] - want) * (px[0] - want) / ((double)px[3] * px[3]);
                noisy++;
            }
            if (err > 5e-3) bad++;
            n++;
        }
    fprintf(stderr, "  %s: worst rel error %.2e, %d noisy pixels, mean z^2 %.2f\n", name, worst,
            noisy, noisy ? z2 / noisy : 0.0);
    CHECK(bad == 0, "%s: %d of %d pixels off by more than 0.5%% (worst %.3g)", name, bad, n, worst);
    if (noisy == 0) {
        // Equi-angular strata make the unshadowed, isotropic, extinction-free
        // integrand constant: no noise, so the answer must be exact.
        CHECK(worst < 1e-5, "%s: zero-variance case off by %.3g", name, worst);
    } else {
        // The reported standard error should describe the actual error: the
        // mean z^2 of a t statistic with spp - 1 = 7 degrees of freedom is 1.4.
        CHECK(noisy == n, "%s: %d of %d pixels without a standard error", name, n - noisy, n);
        CHECK(z2 / noisy > 0.4 && z2 / noisy < 4.0,
              "%s: mean z^2 = %.3g: stderr inconsistent with the error", name, z2 / noisy);
    }
}

static void open_space(void) {
    const struct {
        const char *name;
        double ss, sa;
        st_phase_kind phase;
        double g;
        int kind;
    } cases[] = {
        // sigma_a = -sigma_s gives sigma_t = 0 exactly (the atan form's limit;
        // only an in-memory scene can say so, the parser rejects it).
        {"zero extinction, isotropic vs atan", 0.05, -0.05, ST_PHASE_ISOTROPIC, 0, 0},
        {"sigma_a = sigma_s, isotropic vs Sun", 0.05, 0.05, ST_PHASE_ISOTROPIC, 0, 1},
        {"dense, isotropic vs Sun", 0.3, 0.2, ST_PHASE_ISOTROPIC, 0, 1},
        {"Rayleigh vs quadrature", 0.1, 0.02, ST_PHASE_RAYLEIGH, 0, 2},
        {"HG 0.7 vs quadrature", 0.1, 0.02, ST_PHASE_HG, 0.7, 2},
        {"HG -0.5 vs quadrature", 0.1, 0.02, ST_PHASE_HG, -0.5, 2},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        st_scene s;
        scene_init(&s, 15, 15, cam, tgt, up, 40, far_z);
        add_light(&s, light, I);
        set_medium(&s, cases[k].ss, cases[k].sa, cases[k].phase, cases[k].g);
        st_ref_options o = {.spp = 8, .aov = ST_REF_INSCATTER, .seed = 7 + k};
        st_image img;
        if (render(&s, &o, &img)) {
            check_image(cases[k].name, &s, &img, cases[k].kind);
            // Combined = inscatter here: no surfaces.
            st_ref_options oc = o;
            oc.aov = ST_REF_COMBINED;
            st_image c;
            if (render(&s, &oc, &c)) {
                CHECK(!memcmp(c.data, img.data, sizeof(float) * 6 * 15 * 15),
                      "%s: combined != inscatter", cases[k].name);
                st_image_free(&c);
            }
            st_image_free(&img);
        }
        st_scene_free(&s);
    }
}

// A half-plane occluder at y = 1 over x > 0 shadows every point x > 0 of a
// ray along +x at y = 0 from a light at (0, 2, 0): only the first 5 m of the
// centre pixel's ray (from x = -5) are lit.
static void shadowed(void) {
    const double c[3] = {-5, 0, 0}, t[3] = {0, 0, 0}, u[3] = {0, 1, 0}, l[3] = {0, 2, 0};
    st_scene s;
    scene_init(&s, 15, 15, c, t, u, 30, 50);
    add_light(&s, l, 3.0);
    set_medium(&s, 0.08, 0.04, ST_PHASE_ISOTROPIC, 0);
    add_quad(&s, (double[]){0, 1, -1000}, (double[]){0, 0, 2000}, (double[]){1000, 0, 0}, 0.5, 0);
    st_ref_options o = {.spp = 32, .aov = ST_REF_INSCATTER, .seed = 3};
    st_image img;
    if (render(&s, &o, &img)) {
        double D = sqrt(29.0), gamma = atan2(2.0, 5.0);
        double want = st_inscatter_sun(0.08, 0.12, 3.0, D, gamma, 5.0);
        double unshadowed = st_inscatter_sun(0.08, 0.12, 3.0, D, gamma, 50.0);
        const float *px = st_image_px(&img, 7, 7);
        fprintf(stderr,
                "  shadowed: %.6g (stderr %.2g), Sun over the lit part %.6g, unshadowed %.6g\n",
                px[0], px[3], want, unshadowed);
        CHECK_REL(px[0], want, 5e-3, 0);
        CHECK(unshadowed > 1.05 * want, "the occluder must matter here");
        st_image_free(&img);
    }
    st_scene_free(&s);
}

// combined = (direct + indirect) e^(-sigma_t s) + inscatter, per pixel, with
// s the distance to the surface; bounces = 0 keeps the random streams equal.
static void combined(void) {
    const double c[3] = {0, 1, 4}, t[3] = {0, 0.5, 0}, u[3] = {0, 1, 0}, l[3] = {0.5, 1.5, 0.5};
    st_scene s;
    scene_init(&s, 16, 16, c, t, u, 45, 100);
    add_light(&s, l, 5.0);
    set_medium(&s, 0.2, 0.1, ST_PHASE_HG, 0.3);
    add_quad(&s, (double[]){-3, -1, -1}, (double[]){6, 0, 0}, (double[]){0, 6, 0}, 0.7,
             0.1); // faces +z
    st_ref_options o = {.spp = 4, .seed = 11};
    st_image a[3];
    const st_ref_aov aovs[3] = {ST_REF_COMBINED, ST_REF_DIRECT, ST_REF_INSCATTER};
    bool ok = true;
    for (int k = 0; k < 3; k++) {
        o.aov = aovs[k];
        ok = ok && render(&s, &o, &a[k]);
    }
    if (ok) {
        int bad = 0;
        for (int j = 0; j < 16; j++)
            for (int i = 0; i < 16; i++) {
                double d[3];
                contract_ray(&s, i, j, d);
                double dist = (-1.0 - c[2]) / d[2]; // the wall z = -1
                double want =
                    st_image_px(&a[1], i, j)[0] * exp(-0.3 * dist) + st_image_px(&a[2], i, j)[0];
                if (fabs(st_image_px(&a[0], i, j)[0] - want) > 1e-5 * want) bad++;
            }
        CHECK(bad == 0, "combined != direct e^(-sigma_t s) + inscatter at %d pixels", bad);
    }
    for (int k = 0; k < 3 && ok; k++)
        st_image_free(&a[k]);
    st_scene_free(&s);
}

// ---- directional and spot lights, against adaptive quadrature of integrands
// written out here (docs/physics.md): E e^(-sigma_t path) for the sun, path
// measured from the entry plane touching the scene's bounds; I f / d^2
// e^(-sigma_t d) for the spot with glTF's falloff f.
typedef struct {
    int type; // 1 directional, 2 spot
    double o[3], d[3], ss, st, g;
    double dir[3], entry;   // directional: travel direction, entry
    double cos_in, cos_out; // spot
} lt_problem;

static double lt_integrand(double t, void *ctx) {
    const lt_problem *p = ctx;
    double x[3], l[3], E, path;
    for (int k = 0; k < 3; k++)
        x[k] = p->o[k] + t * p->d[k];
    if (p->type == 1) {
        for (int k = 0; k < 3; k++)
            l[k] = -p->dir[k];
        path = fmax(0.0, p->entry - (x[0] * l[0] + x[1] * l[1] + x[2] * l[2]));
        E = I;
    } else {
        double v[3] = {light[0] - x[0], light[1] - x[1], light[2] - x[2]};
        double d = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int k = 0; k < 3; k++)
            l[k] = v[k] / d;
        double a = (-(l[0] * p->dir[0] + l[1] * p->dir[1] + l[2] * p->dir[2]) - p->cos_out) /
                   fmax(0.001, p->cos_in - p->cos_out);
        a = fmin(fmax(a, 0.0), 1.0);
        E = I * a * a / (d * d), path = d;
    }
    double c = l[0] * p->d[0] + l[1] * p->d[1] + l[2] * p->d[2];
    double ph = (1 - p->g * p->g) / (4 * ST_PI * pow(1 + p->g * p->g - 2 * p->g * c, 1.5));
    return exp(-p->st * (t + path)) * p->ss * ph * E;
}

static void light_types(void) {
    const double sun[3] = {0.3 / 1.0630146, -1 / 1.0630146, 0.2 / 1.0630146}; // unit
    const double axis[3] = {-0.2 / 1.0198039, -1 / 1.0198039, 0};
    for (int type = 1; type <= 2; type++) {
        st_scene s;
        scene_init(&s, 15, 15, cam, tgt, up, 40, far_z);
        // Far behind the camera, out of every ray's way: it only gives the scene bounds.
        add_quad(&s, (double[]){-1, -1, 30}, (double[]){2, 0, 0}, (double[]){0, 2, 0}, 0.5, 0);
        st_light_desc l = {0};
        l.type = type == 1 ? ST_LIGHT_DIRECTIONAL : ST_LIGHT_SPOT;
        for (int k = 0; k < 3; k++) {
            l.position[k] = (float)light[k], l.intensity[k] = (float)I;
            l.direction[k] = (float)(type == 1 ? sun[k] : axis[k]);
        }
        l.inner_angle = (float)(15 * ST_PI / 180), l.outer_angle = (float)(40 * ST_PI / 180);
        st_err err = {0};
        CHECK(st_scene_add_light(&s, &l, &err), "add light");
        set_medium(&s, 0.1, 0.05, ST_PHASE_HG, 0.4);
        st_ref_options o = {.spp = 8, .aov = ST_REF_INSCATTER, .seed = 40 + type};
        st_image img;
        if (!render(&s, &o, &img)) continue;
        lt_problem p = {type,
                        {cam[0], cam[1], cam[2]},
                        {0},
                        0.1,
                        0.15,
                        0.4,
                        {0},
                        0,
                        cos(l.inner_angle),
                        cos(l.outer_angle)};
        for (int k = 0; k < 3; k++)
            p.dir[k] = l.direction[k];
        p.entry = -INFINITY; // the quad's corners
        for (int k = 0; k < 4; k++) {
            double c[3] = {k & 1 ? 1 : -1, k & 2 ? 1 : -1, 30};
            p.entry = fmax(p.entry, -(c[0] * p.dir[0] + c[1] * p.dir[1] + c[2] * p.dir[2]));
        }
        double worst = 0, z2 = 0, mean = 0, wants[15][15];
        int n = 0, lit = 0;
        for (int j = 0; j < 15; j++)
            for (int i = 0; i < 15; i++) {
                contract_ray(&s, i, j, p.d);
                wants[j][i] = st_integrate(lt_integrand, &p, 0, far_length(&s, p.d), 1e-14, 1e-10);
                mean += wants[j][i] / (15 * 15);
            }
        for (int j = 0; j < 15; j++)
            for (int i = 0; i < 15; i++) {
                double want = wants[j][i];
                const float *px = st_image_px(&img, i, j);
                n++;
                // Rays that graze the cone: quadrature and march both ~0.
                if (!(want > 1e-3 * mean)) {
                    CHECK(px[0] <= 2e-3 * mean, "%s: pixel (%d %d) outside the light: %g (mean %g)",
                          type == 1 ? "sun" : "spot", i, j, px[0], mean);
                    continue;
                }
                lit++;
                worst = fmax(worst, fabs(px[0] - want) / want);
                if (px[3] > 0) z2 += (px[0] - want) * (px[0] - want) / ((double)px[3] * px[3]);
            }
        fprintf(stderr,
                "  %s in-scatter: worst rel error %.2e over %d lit of %d pixels, mean z^2 %.2f\n",
                type == 1 ? "directional" : "spot", worst, lit, n, lit ? z2 / lit : 0.0);
        CHECK(lit > 50, "%s: %d pixels see the light", type == 1 ? "sun" : "spot", lit);
        CHECK(worst < 5e-3, "%s in-scatter: worst relative error %.3g", type == 1 ? "sun" : "spot",
              worst);
        CHECK(z2 / lit < 4.0, "%s: mean z^2 %.3g: stderr inconsistent with the error",
              type == 1 ? "sun" : "spot", z2 / lit);
        st_image_free(&img);
        st_scene_free(&s);
    }
}

int main(void) {
    open_space();
    light_types();
    shadowed();
    combined();
    return st_test_summary("reference_inscatter");
}
