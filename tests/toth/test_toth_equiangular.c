// Equi-angular sampling (sampling=equiangular, the default) in the singular
// and grazing configurations: the light on a pixel's centre ray, at the
// camera, behind it on the view axis (rays pointing straight away from it),
// on the wall a pixel sees (the ray ends at the light). In C, the
// Gauss-Legendre rule in theta (framework/st_physics.c) against adaptive
// quadrature and Sun et al.'s closed form; on the GPU every pixel of the
// defaults against that rule with 64 nodes and the same light-ray distance
// clamp (a quarter pixel at the light's distance), all finite.
#include "toth_test.h"

enum { N = 64 };
static const double SS = 0.2, SA = 0.05, I = 10;

// The shader's clamp: a quarter of a pixel at the light's distance (at least
// the near plane, 0.05 in the test room).
static double h_min(double D) {
    double pixel = 2.0 * tan(ROOM_FOV * ST_PI / 360.0) / N;
    return 0.25 * pixel * fmax(D, 0.05);
}

static double quad_split(const st_inscatter_problem *p) {
    double foot = 0, dl = 0;
    for (int k = 0; k < 3; k++)
        foot += (p->light[k] - p->origin[k]) * p->dir[k], dl += p->dir[k] * p->dir[k];
    foot /= sqrt(dl);
    if (foot <= 0 || foot >= p->length) return toth_quad_oracle(p);
    return st_integrate(toth_integrand_cb, (void *)p, 0.0, foot, 1e-300, 1e-11) +
           st_integrate(toth_integrand_cb, (void *)p, foot, p->length, 1e-300, 1e-11);
}

// The rule against quadrature on every room pixel (lights off the rays) and
// against Sun et al. for the isotropic medium.
static void test_rule(const st_test_cam *c) {
    const double light[3] = {0.8, 2.5, -0.9};
    const st_phase_kind kinds[3] = {ST_PHASE_ISOTROPIC, ST_PHASE_HG, ST_PHASE_RAYLEIGH};
    for (int k = 0; k < 3; k++) {
        double worst16 = 0, worst64 = 0, worst_sun = 0;
        for (int j = 0; j < N; j += 3)
            for (int i = 0; i < N; i += 3) {
                st_inscatter_problem p =
                    toth_room_problem(c, i, j, light, I, SS, SS + SA, kinds[k], 0.5);
                double q = quad_split(&p);
                worst16 = fmax(worst16, fabs(st_inscatter_equiangular(&p, 16, 0) / q - 1));
                worst64 = fmax(worst64, fabs(st_inscatter_equiangular(&p, 64, 0) / q - 1));
                if (k == 0) worst_sun = fmax(worst_sun, fabs(st_inscatter_sun_problem(&p) / q - 1));
            }
        printf("  phase %d: Gauss-Legendre in theta vs quadrature: 16 nodes %.2e, 64 nodes %.2e; "
               "Sun %.2e\n",
               k, worst16, worst64, worst_sun);
        CHECK(worst16 < 1e-3 && worst64 < 1e-6, "phase %d: 16 nodes %.3g, 64 nodes %.3g", k,
              worst16, worst64);
        CHECK(worst_sun < 1e-6, "Sun et al. vs quadrature %.3g", worst_sun);
    }
    // A ray through the light: the unclamped integral diverges like 1/h.
    st_inscatter_problem p =
        toth_room_problem(c, 11, 7, light, I, SS, SS + SA, ST_PHASE_ISOTROPIC, 0);
    for (int k = 0; k < 3; k++)
        p.light[k] = p.origin[k] + 1.7 * p.dir[k];
    double a = st_inscatter_equiangular(&p, 64, 1e-3), b = st_inscatter_equiangular(&p, 64, 1e-4);
    printf("  light on the ray: h clamped to 1e-3: %.4g, 1e-4: %.4g\n", a, b);
    CHECK(isfinite(a) && isfinite(b) && fabs(b / a - 10) < 0.1,
          "on the ray: 1/h growth %.4g / %.4g", b, a);
}

// GPU defaults against the rule, one light position at a time.
static void test_gpu(const st_test_cam *c, const char *name, const double light[3]) {
    char scene[512], out[512], med[128];
    snprintf(scene, sizeof scene, "%s/eq.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/eq.exr", ST_TEST_SCRATCH);
    snprintf(med, sizeof med, "\"sigma_s\": [%g, %g, %g], \"sigma_a\": [%g, %g, %g]", SS, SS, SS,
             SA, SA, SA);
    const double Iv[3] = {I, I, I};
    toth_write_room(scene, N, light, Iv, 0.0, med, "");
    st_image img = {0};
    if (!toth_render(scene, out, NULL, &img)) return;
    double rel = 0, D = 0, vmax = 0;
    for (int k = 0; k < 3; k++)
        D += (light[k] - c->pos[k]) * (light[k] - c->pos[k]);
    D = sqrt(D);
    static double want[N][N];
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            st_inscatter_problem p =
                toth_room_problem(c, i, j, light, I, SS, SS + SA, ST_PHASE_ISOTROPIC, 0);
            want[j][i] = st_inscatter_equiangular(&p, 64, h_min(D));
            vmax = fmax(vmax, want[j][i]);
        }
    int counted = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            if (want[j][i] <= 0.02 * vmax) continue;
            counted++;
            for (int ch = 0; ch < 3; ch++)
                rel = fmax(rel, fabs(st_image_px(&img, i, j)[ch] / want[j][i] - 1));
        }
    printf("  %-10s max %.4g, %d px above 2%% of it: worst %.2e\n", name, vmax, counted, rel);
    CHECK(isfinite(vmax) && counted > 0, "%s: a finite, non-empty oracle", name);
    CHECK(rel < 0.01, "%s: worst pixel %.4f off the rule", name, rel);
    st_image_free(&img);
}

int main(void) {
    st_test_cam c = st_test_camera(ROOM_CAM, ROOM_TGT, ROOM_UP, ROOM_FOV, N, N);
    test_rule(&c);
    double on_ray[3], on_wall[3], behind[3], d[3];
    st_test_ray(&c, 11, 7, d);
    for (int k = 0; k < 3; k++)
        on_ray[k] = c.pos[k] + 1.7 * d[k];
    st_test_ray(&c, 40, 30, d);
    double s = toth_box_exit(c.pos, d, ROOM_MIN, ROOM_MAX);
    for (int k = 0; k < 3; k++)
        on_wall[k] = c.pos[k] + 0.999 * s * d[k], behind[k] = c.pos[k] - 0.4 * c.f[k];
    test_gpu(&c, "on a ray", on_ray);
    test_gpu(&c, "at camera", ROOM_CAM);
    test_gpu(&c, "behind", behind);
    test_gpu(&c, "at wall", on_wall);
    return st_test_summary("toth_equiangular");
}
