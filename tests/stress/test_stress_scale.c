// Scale stress: a Cornell-like box at scale 1, 1e-3 and 1e4 (every length
// times s, near/far times s, light intensity times s^2, medium coefficients
// divided by s) is the same picture in physical units: radiance depends on
// I / d^2, cosines and optical depths only. Every configuration must render
// the scaled boxes with every value finite and, where the technique is
// scale-free, within a few % of the unscaled image; the CPU reference too.
#include "stress.h"

enum { N = 32 };

static char json[16384];

// Cornell box of scenes/cornell.json (open front, two blocks), scaled.
static void cornell(double s, const stress_config *c, const char *module_params) {
    // Quads: corner, u, v; then the two blocks' min/max.
    static const double quads[5][9] = {
        {-1, 0, -1, 0, 0, 2, 2, 0, 0}, {-1, 2, -1, 2, 0, 0, 0, 0, 2}, {-1, 0, -1, 2, 0, 0, 0, 2, 0},
        {-1, 0, -1, 0, 2, 0, 0, 0, 2}, {1, 0, -1, 0, 0, 2, 0, 2, 0},
    };
    static const double albedo[5][3] = {{0.75, 0.75, 0.75},
                                        {0.75, 0.75, 0.75},
                                        {0.75, 0.75, 0.75},
                                        {0.75, 0.1, 0.1},
                                        {0.1, 0.75, 0.1}};
    static const double blocks[2][6] = {{0.1, 0, -0.1, 0.7, 0.6, 0.5},
                                        {-0.7, 0, -0.7, -0.1, 1.2, -0.1}};
    char geo[4096] = "", med[256] = "";
    size_t n = 0;
    for (int q = 0; q < 5; q++) {
        const double *v = quads[q];
        n += (size_t)snprintf(
            geo + n, sizeof geo - n,
            "%s{\"quad\": {\"corner\": [%.17g, %.17g, %.17g], \"u\": [%.17g, %.17g, %.17g],"
            " \"v\": [%.17g, %.17g, %.17g]}, \"albedo\": [%g, %g, %g]}",
            q ? ", " : "", s * v[0], s * v[1], s * v[2], s * v[3], s * v[4], s * v[5], s * v[6],
            s * v[7], s * v[8], albedo[q][0], albedo[q][1], albedo[q][2]);
    }
    for (int b = 0; b < 2; b++) {
        const double *v = blocks[b];
        n += (size_t)snprintf(
            geo + n, sizeof geo - n,
            ", {\"box\": {\"min\": [%.17g, %.17g, %.17g], \"max\": [%.17g, %.17g, %.17g]}}",
            s * v[0], s * v[1], s * v[2], s * v[3], s * v[4], s * v[5]);
    }
    if (c->medium)
        snprintf(
            med, sizeof med,
            " \"medium\": {\"sigma_s\": [%.17g, %.17g, %.17g], \"sigma_a\": [%.17g, %.17g, %.17g],"
            " \"phase\": {\"hg\": 0.3}},",
            0.3 / s, 0.2 / s, 0.1 / s, 0.02 / s, 0.02 / s, 0.02 / s);
    double I = 3 * s * s;
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},"
             " \"camera\": {\"position\": [0, %.17g, %.17g], \"target\": [0, %.17g, 0], \"up\": "
             "[0, 1, 0],"
             " \"fov_y\": 40, \"near\": %.17g, \"far\": %.17g},"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, %.17g, 0], \"intensity\": "
             "[%.17g, %.17g, %.17g]}],"
             " \"geometry\": [%s],%s \"modules\": %s}",
             N, N, s * 1, s * 3.4, s * 1, s * 0.05, s * 100, s * 1.9, I, I, I, geo, med,
             module_params ? module_params : c->modules);
}

int main(void) {
    double t0 = stress_now();
    const double scales[] = {1e-3, 1e4};
    char name[96];
    for (int m = 0; m < STRESS_NUM_CONFIGS; m++) {
        const stress_config *c = &stress_configs[m];
        int mitchell = !strcmp(c->name, "mitchell");
        for (int k = 0; k < 2; k++) {
            double s = scales[k];
            // mitchell's light disc has a radius in metres: it scales with
            // the scene. Its range [0.001, 100] holds no radius r with both
            // r 1e-3 and r 1e4 inside, so each scale has its own unscaled
            // twin: r = 1 for 1e-3, r = 0.005 for 1e4.
            char base_mods[512], mods[512];
            double r = s < 1 ? 1.0 : 0.005;
            snprintf(base_mods, sizeof base_mods,
                     "[{\"name\": \"mitchell\", \"params\": {\"n\": 32, \"light_radius\": %.17g}}]",
                     r);
            snprintf(mods, sizeof mods,
                     "[{\"name\": \"mitchell\", \"params\": {\"n\": 32, \"light_radius\": %.17g}}]",
                     r * s);
            st_image base = {0}, img = {0};
            cornell(1, c, mitchell ? base_mods : NULL);
            snprintf(name, sizeof name, "scale_1_%s_%d", c->name, k);
            if (!stress_render(name, json, NULL, &base)) continue;
            cornell(s, c, mitchell ? mods : NULL);
            snprintf(name, sizeof name, "scale_%g_%s", s, c->name);
            if (stress_render(name, json, NULL, &img)) {
                stress_stats a = stress_image_stats(&img), b = stress_image_stats(&base);
                double d = stress_rel_l1(&img, &base);
                printf("  %-26s mean %.6g (unscaled %.6g), relative L1 difference %.2e\n", name,
                       a.mean, b.mean, d);
                CHECK(a.negative == 0, "%s: %zu negative values", name, a.negative);
                CHECK(d < 0.03, "%s: relative L1 difference from the unscaled image %.3g", name, d);
                CHECK_REL(a.mean, b.mean, 0.01, 0);
            }
            st_image_free(&img);
            st_image_free(&base);
        }
    }
    // The CPU reference (direct and one bounce, exact visibility), same seed.
    st_image base = {0};
    cornell(1, &stress_configs[0], NULL);
    if (stress_ok("reference", "scale_1_reference", json, "--spp 4 --seed 7", &base)) {
        for (int k = 0; k < 2; k++) {
            cornell(scales[k], &stress_configs[0], NULL);
            snprintf(name, sizeof name, "scale_%g_reference", scales[k]);
            st_image img = {0};
            if (!stress_ok("reference", name, json, "--spp 4 --seed 7", &img)) continue;
            double d = stress_rel_l1(&img, &base);
            printf("  %-26s relative L1 difference %.2e\n", name, d);
            CHECK(d < 0.03, "%s: relative L1 difference from the unscaled image %.3g", name, d);
            st_image_free(&img);
        }
    }
    st_image_free(&base);
    printf("  %.1f s\n", stress_now() - t0);
    return st_test_summary("test_stress_scale");
}
