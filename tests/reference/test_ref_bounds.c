// The reference's tracking is bounded (issue 36, item 1): steep height fog
// (falloff 1e4 m^-1, more than 64 e-folds of density along a ray) is tracked
// in pieces whose collisions stay bounded, and its transmittance still
// matches the closed form of st_physics.c (the ratio tracking is unbiased
// whatever the pieces); a VDB medium too dense to track at all is refused.
// Without the bound the first check never finishes (ctest's timeout).
#include "ref_test_util.h"

// Mean of n ratio-tracking estimates against e^(-sigma_t tau), tau from the
// closed form, within 5 standard errors (plus a little for T near 0 or 1).
static void steep_segment(const double o[3], const double w[3], double L, const char *what) {
    st_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.density = (st_density_desc){.kind = ST_DENSITY_HEIGHT, .base = 0.069, .falloff = 1e4};
    st_ref_geometry g = {.desc = &sc, .sigma_t = {1.0, 0.5, 2.0}};
    st_ref_rng rng;
    st_ref_rng_seed(&rng, 36, 1);
    const int n = 20000;
    double sum[3] = {0}, sum2[3] = {0};
    for (int i = 0; i < n; i++) {
        double T[3];
        st_ref_transmittance(&g, o, w, 0.0, L, &rng, T);
        for (int c = 0; c < 3; c++)
            sum[c] += T[c], sum2[c] += T[c] * T[c];
    }
    double tau = st_density_integral(&sc.density, o, w, 0.0, L);
    fprintf(stderr, "  %s: tau %.4f, mean T %.4f %.4f %.4f\n", what, tau, sum[0] / n, sum[1] / n,
            sum[2] / n);
    for (int c = 0; c < 3; c++) {
        double mean = sum[c] / n, var = fmax(sum2[c] / n - mean * mean, 0.0);
        double want = exp(-g.sigma_t[c] * tau);
        CHECK(fabs(mean - want) <= 5.0 * sqrt(var / n) + 2e-3,
              "%s, channel %d: mean T %.5f, closed form %.5f (tau %.4g, stderr %.2g)", what, c,
              mean, want, tau, sqrt(var / n));
    }
}

static void steep_height_fog(void) {
    // Down from y = 1 to just below the base, where tau is about 1 (the
    // density rises by e^9000 on the way), then the same segment upward,
    // and an oblique one through the steep layer.
    const double down[3] = {0, -1, 0}, up[3] = {0, 1, 0};
    const double o_down[3] = {0.2, 1.0, 0.0}, o_up[3] = {0.2, 0.0681, 0.0};
    steep_segment(o_down, down, 1.0 - 0.0681, "steep fog, downward");
    steep_segment(o_up, up, 1.0 - 0.0681, "steep fog, upward");
    double w[3] = {0.9, -0.05, 0.1}, l = sqrt(0.81 + 0.0025 + 0.01);
    for (int k = 0; k < 3; k++)
        w[k] /= l;
    const double o[3] = {-1.0, 0.08, 0.0}; // 116 e-folds down to y = 0.0684
    steep_segment(o, w, (0.08 - 0.0684) / -w[1], "steep fog, oblique");
}

// A VDB medium with sigma_s 1e20 would need ~1e20 collisions per ray: refused
// before rendering, with a message naming the scene; sigma_s 1 is accepted.
static void dense_grid_refused(void) {
    st_density_grid grid = {.n = {3, 3, 3}, .max_value = 1.0, .bmin = {0, 0, 0}, .bmax = {2, 2, 1}};
    st_scene sc;
    memset(&sc, 0, sizeof sc);
    snprintf(sc.path, sizeof sc.path, "dense.json");
    sc.medium.present = true;
    sc.density = (st_density_desc){.kind = ST_DENSITY_GRID, .grid = &grid};
    for (int c = 0; c < 3; c++)
        sc.medium.sigma_s[c] = 1e20f;
    st_err err = {0};
    CHECK(!st_ref_medium_check(&sc, &err) && err.kind == ST_ERR_INPUT &&
              strstr(err.msg, "dense.json") && strstr(err.msg, "tentative collisions"),
          "sigma_s 1e20 in a grid: %s", err.msg);
    for (int c = 0; c < 3; c++)
        sc.medium.sigma_s[c] = 1.0f;
    err = (st_err){0};
    CHECK(st_ref_medium_check(&sc, &err), "sigma_s 1 in a grid: %s", err.msg);
}

int main(void) {
    steep_height_fog();
    dense_grid_refused();
    return st_test_summary("reference_bounds");
}
