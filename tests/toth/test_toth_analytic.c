// toth against closed forms, no shadows (a closed room, the light inside it
// out of view): zero extinction vs the atan form, extinction vs Sun et al.
// 2005, anisotropic phase functions vs adaptive quadrature, convergence in
// the sample count, and the composition L_surface e^(-sigma_t s) + L_in.
#include "toth_test.h"

enum { N = 64 };
static const double LIGHT[3] = {0.8, 2.9, -0.5}, I[3] = {10, 10, 10};
static char scene[512], out[512];
static st_test_cam cam;

typedef struct {
    double worst, mean;
} err_stats;

// Renders the room and compares every pixel and channel with the oracle
// (0: atan, 1: Sun et al., 2: quadrature).
static err_stats run(const double ss[3], const double sa[3], const char *phase, st_phase_kind kind,
                     double g, int oracle, const char *toth_params) {
    char medium[256];
    snprintf(medium, sizeof medium,
             "\"sigma_s\": [%g, %g, %g], \"sigma_a\": [%g, %g, %g], \"phase\": %s", ss[0], ss[1],
             ss[2], sa[0], sa[1], sa[2], phase);
    toth_write_room(scene, N, LIGHT, I, 0.0, medium, toth_params);
    err_stats e = {1e9, 1e9};
    st_image img = {0};
    if (!toth_render(scene, out, NULL, &img)) return e;
    e.worst = e.mean = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                st_inscatter_problem p =
                    toth_room_problem(&cam, i, j, LIGHT, I[c], ss[c], ss[c] + sa[c], kind, g);
                double want = oracle == 0   ? toth_atan_oracle(&p)
                              : oracle == 1 ? st_inscatter_sun_problem(&p)
                                            : toth_quad_oracle(&p);
                double rel = fabs(st_image_px(&img, i, j)[c] - want) / want;
                e.worst = fmax(e.worst, rel);
                e.mean += rel / (3.0 * N * N);
            }
    st_image_free(&img);
    printf("  %-10s %-36s worst %.3e mean %.3e\n", phase, toth_params, e.worst, e.mean);
    return e;
}

// Both samplings: the uniform march of 64 steps, and the defaults
// (equi-angular: Gauss-Legendre per pixel, visibility at reduced resolution).
static const char *EXACT_MODES[2] = {"\"sampling\": \"uniform\", \"samples\": 64, \"interleave\": "
                                     "1, \"jitter\": false, \"resolution\": \"full\"",
                                     "\"sampling\": \"equiangular\""};
static const char *EXACT;

// sigma_t >= sigma_s > 0, so "zero extinction" is the limit sigma_t (t + d)
// -> 0: at sigma_t = 1e-4 and paths under 10 m the atan form is within 0.1%
// of the attenuated integral (checked below), leaving the rest of the 1% to
// the march.
static void test_zero_extinction(void) {
    const double ss[3] = {1e-4, 1e-4, 1e-4}, sa[3] = {0, 0, 0};
    st_inscatter_problem p =
        toth_room_problem(&cam, 0, 0, LIGHT, I[0], ss[0], ss[0], ST_PHASE_ISOTROPIC, 0);
    CHECK(fabs(toth_atan_oracle(&p) / toth_quad_oracle(&p) - 1) < 1e-3,
          "the atan form is the sigma_t -> 0 limit");
    err_stats e = run(ss, sa, "\"isotropic\"", ST_PHASE_ISOTROPIC, 0, 0, EXACT);
    CHECK(e.worst < 0.01, "zero extinction vs atan form: worst %.4g", e.worst);
}

static void test_extinction(void) {
    const double ss[3] = {0.1, 0.2, 0.3}, sa[3] = {0.2, 0.1, 0.05};
    err_stats e = run(ss, sa, "\"isotropic\"", ST_PHASE_ISOTROPIC, 0, 1, EXACT);
    CHECK(e.worst < 0.01, "extinction vs Sun et al.: worst %.4g", e.worst);
    // Anisotropic phase functions through the same march (the cosine convention included).
    e = run(ss, sa, "{\"hg\": 0.5}", ST_PHASE_HG, 0.5, 2, EXACT);
    CHECK(e.worst < 0.01, "HG 0.5 vs quadrature: worst %.4g", e.worst);
    e = run(ss, sa, "{\"hg\": -0.9}", ST_PHASE_HG, -0.9, 2, EXACT);
    CHECK(e.worst < 0.01, "HG -0.9 vs quadrature: worst %.4g", e.worst);
    e = run(ss, sa, "\"rayleigh\"", ST_PHASE_RAYLEIGH, 0, 2, EXACT);
    CHECK(e.worst < 0.01, "Rayleigh vs quadrature: worst %.4g", e.worst);
}

// Several lights add up: two lights (one of them behind the camera), and
// five (equi-angular sampling gives lights 3 and 4 one shared visible
// fraction: exact here, where nothing casts a shadow into the medium)
// against the sum of their Sun et al. integrals.
static void test_lights(int n) {
    const double L5[5][3] = {
        {0.8, 2.9, -0.5}, {-1.5, 0.4, 1.8}, {1.2, 1.0, 0.5}, {-0.5, 2.0, -1.5}, {0.0, 0.3, 0.0}};
    const double I5[5][3] = {{10, 10, 10}, {1, 4, 8}, {3, 2, 1}, {5, 5, 5}, {2, 1, 3}};
    const double ss[3] = {0.1, 0.2, 0.3}, sa[3] = {0.2, 0.1, 0.05};
    toth_write_room_n(scene, N, n, L5, I5, 0.0,
                      "\"sigma_s\": [0.1, 0.2, 0.3], \"sigma_a\": [0.2, 0.1, 0.05]", EXACT);
    st_image img = {0};
    if (!toth_render(scene, out, NULL, &img)) return;
    double worst = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                double want = 0;
                for (int k = 0; k < n; k++) {
                    st_inscatter_problem p = toth_room_problem(
                        &cam, i, j, L5[k], I5[k][c], ss[c], ss[c] + sa[c], ST_PHASE_ISOTROPIC, 0);
                    want += st_inscatter_sun_problem(&p);
                }
                worst = fmax(worst, fabs(st_image_px(&img, i, j)[c] - want) / want);
            }
    printf("  %d lights: worst %.3e\n", n, worst);
    CHECK(worst < 0.01, "%d lights vs the sum of Sun et al.: worst %.4g", n, worst);
    st_image_free(&img);
}

// The error falls as the sample count grows, with samples at the step
// midpoints and jittered within their steps. (Interleaving adds an error of
// its own, from the neighbours' rays; tested in test_toth_interleave.)
static void test_convergence(void) {
    const double ss[3] = {0.1, 0.2, 0.3}, sa[3] = {0.2, 0.1, 0.05};
    const char *modes[] = {
        "\"sampling\": \"uniform\", \"interleave\": 1, \"jitter\": false, \"resolution\": \"full\"",
        "\"sampling\": \"uniform\", \"interleave\": 1, \"jitter\": true, \"resolution\": \"full\""};
    for (int m = 0; m < 2; m++) {
        err_stats e[3];
        const int n[3] = {8, 32, 128};
        for (int k = 0; k < 3; k++) {
            char params[256];
            snprintf(params, sizeof params, "\"samples\": %d%s%s", n[k], modes[m][0] ? ", " : "",
                     modes[m]);
            e[k] = run(ss, sa, "\"isotropic\"", ST_PHASE_ISOTROPIC, 0, 1, params);
        }
        CHECK(e[0].mean > e[1].mean && e[1].mean > e[2].mean,
              "mode %d: mean error falls: %.3g %.3g %.3g", m, e[0].mean, e[1].mean, e[2].mean);
        CHECK(e[0].worst > e[1].worst && e[1].worst > e[2].worst,
              "mode %d: worst error falls: %.3g %.3g %.3g", m, e[0].worst, e[1].worst, e[2].worst);
    }
}

// Surface extinction: with walls of albedo 0.5, the image is the surface lit
// without medium times e^(-sigma_t (d + s)) -- d from the light to the
// surface point, s from there to the camera -- plus the in-scatter of the
// black room.
static void test_compose(void) {
    const char *med = "\"sigma_s\": [0.1, 0.2, 0.3], \"sigma_a\": [0.2, 0.1, 0.05]";
    const double st[3] = {0.3, 0.3, 0.35};
    st_image surf = {0}, black = {0}, both = {0};
    toth_write_room(scene, N, LIGHT, I, 0.5, NULL, EXACT);
    int ok = toth_render(scene, out, NULL, &surf);
    toth_write_room(scene, N, LIGHT, I, 0.0, med, EXACT);
    ok = ok && toth_render(scene, out, NULL, &black);
    toth_write_room(scene, N, LIGHT, I, 0.5, med, EXACT);
    ok = ok && toth_render(scene, out, NULL, &both);
    if (ok) {
        double worst = 0, mean_surf = 0;
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                double d[3];
                st_test_ray(&cam, i, j, d);
                double s = toth_box_exit(cam.pos, d, ROOM_MIN, ROOM_MAX), dl2 = 0;
                for (int k = 0; k < 3; k++)
                    dl2 += pow(LIGHT[k] - (cam.pos[k] + s * d[k]), 2);
                for (int c = 0; c < 3; c++) {
                    double want = st_image_px(&surf, i, j)[c] * exp(-st[c] * (s + sqrt(dl2))) +
                                  st_image_px(&black, i, j)[c];
                    worst = fmax(worst, fabs(st_image_px(&both, i, j)[c] - want) / want);
                    mean_surf += st_image_px(&surf, i, j)[c] / (3.0 * N * N);
                }
            }
        printf("  compose: worst %.3e (mean surface radiance %.3g)\n", worst, mean_surf);
        CHECK(mean_surf > 0.05, "the walls are lit: %.3g", mean_surf);
        CHECK(worst < 1e-4, "L_surface e^(-sigma_t s) + L_in: worst %.3g", worst);
    }
    st_image_free(&surf);
    st_image_free(&black);
    st_image_free(&both);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/room.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/room.exr", ST_TEST_SCRATCH);
    cam = st_test_camera(ROOM_CAM, ROOM_TGT, ROOM_UP, ROOM_FOV, N, N);
    for (int m = 0; m < 2; m++) {
        EXACT = EXACT_MODES[m];
        test_zero_extinction();
        test_extinction();
        test_lights(2);
        // Lights near the view rays: the uniform 64-step march misses their
        // 1/d^2 peaks (38% off here), the equi-angular rule does not.
        if (m == 1) test_lights(5);
        test_compose();
    }
    test_convergence();
    return st_test_summary("toth_analytic");
}
