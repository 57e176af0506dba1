// compose=table (the default): a point light's unshadowed in-scattering from
// the airlight table (modules/toth/airlight.h) against
//   - 256-node Gauss-Legendre in the equi-angular angle (st_physics.c) over
//     random rays, lights and extinctions, per phase function: at most 3e-3
//     relative, rms over the rays under 3e-4 (16 nodes, the quadrature
//     default: 4e-3 at HG 0.8);
//   - compose=quadrature with 64 nodes, rendered: every pixel of the lit room
//     within 2e-3 relative.
#include "toth_test.h" // first: it defines _GNU_SOURCE

#include "airlight.h"

static float table[TOTH_AIRLIGHT_NU * TOTH_AIRLIGHT_NXI];

static double urand(unsigned *s) {
    *s = *s * 1664525u + 1013904223u;
    return (*s >> 8) / 16777216.0;
}

static void test_table(st_phase_kind kind, double g, const char *name) {
    toth_airlight_fill(table, kind, g);
    unsigned seed = 7;
    double worst = 0, sum = 0;
    const int n = 1500;
    for (int i = 0; i < n; i++) {
        st_inscatter_problem p = {.intensity = 100, .sigma_s = 0.06, .phase = kind, .g = g};
        double len = 0;
        for (int c = 0; c < 3; c++) {
            p.light[c] = (urand(&seed) - 0.5) * 16;
            p.dir[c] = urand(&seed) - 0.5;
            len += p.dir[c] * p.dir[c];
        }
        for (int c = 0; c < 3; c++)
            p.dir[c] /= sqrt(len);
        p.length = 0.05 + 40 * urand(&seed);
        p.sigma_t = 0.02 + 0.3 * urand(&seed);
        double want = st_inscatter_equiangular(&p, 256, 1e-3);
        double got = toth_airlight_inscatter(table, &p, 1e-3);
        double rel = fabs(got - want) / want;
        worst = fmax(worst, rel);
        sum += rel * rel;
    }
    double rms = sqrt(sum / n);
    printf("  %-10s table vs 256 nodes: worst %.2e, rms %.2e\n", name, worst, rms);
    CHECK(worst < 3e-3 && rms < 3e-4, "%s: table worst %.3g (< 3e-3), rms %.3g (< 3e-4)", name,
          worst, rms);
}

// The lit room (test_toth_analytic's, HG 0.5, albedo 0.5 walls), both
// compose methods, in-scattering only where the two differ.
static void test_render(void) {
    enum { N = 64 };
    static const double LIGHT[3] = {0.8, 2.9, -0.5}, I[3] = {10, 10, 10};
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/room.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/room.exr", ST_TEST_SCRATCH);
    toth_write_room(scene, N, LIGHT, I, 0.0,
                    "\"sigma_s\": [0.1, 0.2, 0.3], \"sigma_a\": [0.2, 0.1, 0.05], \"phase\": "
                    "{\"hg\": 0.5}",
                    NULL);
    st_image a = {0}, b = {0};
    if (!toth_render(scene, out, "--set toth.compose=table", &a) ||
        !toth_render(scene, out, "--set toth.compose=quadrature --set toth.nodes=64", &b)) {
        st_image_free(&a);
        return;
    }
    double worst = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                double x = st_image_px(&a, i, j)[c], y = st_image_px(&b, i, j)[c];
                worst = fmax(worst, fabs(x - y) / y);
            }
    printf("  rendered room, table vs 64 nodes: worst pixel %.2e\n", worst);
    CHECK(worst < 2e-3, "table vs quadrature: worst pixel %.3g (< 2e-3)", worst);
    st_image_free(&a);
    st_image_free(&b);
}

int main(void) {
    test_table(ST_PHASE_ISOTROPIC, 0, "isotropic");
    test_table(ST_PHASE_HG, 0.5, "HG 0.5");
    test_table(ST_PHASE_HG, -0.9, "HG -0.9");
    test_table(ST_PHASE_RAYLEIGH, 0, "Rayleigh");
    test_render();
    return st_test_summary("test_toth_airlight");
}
