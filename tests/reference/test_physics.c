// The radiometric model against analytic oracles: phase normalization,
// the march integrators, Sun et al. vs brute-force quadrature, form factors.
#include "st_test.h"
#include "st_physics.h"

typedef struct {
    int kind; // 0 HG, 1 Rayleigh, 2 HG thesis, 3 Rayleigh thesis, 4 isotropic
    double g;
} phase_ctx;

static double phase_f(double c, void *vctx) {
    const phase_ctx *p = vctx;
    switch (p->kind) {
    case 0:
        return st_phase_hg(c, p->g);
    case 1:
        return st_phase_rayleigh(c);
    case 2:
        return st_phase_hg_thesis(c, p->g);
    case 3:
        return st_phase_rayleigh_thesis(c);
    default:
        return st_phase_isotropic();
    }
}

// Integral over the sphere = 2 pi integral_-1^1 p(cos) dcos.
static double sphere_integral(int kind, double g) {
    phase_ctx c = {kind, g};
    return 2.0 * ST_PI * st_integrate(phase_f, &c, -1.0, 1.0, 1e-14, 1e-12);
}

static void test_phase(void) {
    const double gs[] = {-0.9, 0.0, 0.5, 0.9, 0.999};
    for (int i = 0; i < 5; i++) {
        CHECK_REL(sphere_integral(0, gs[i]), 1.0, 1e-9, 0);
        // The thesis' HG: 2 pi (1-g)^2 / (2g) ln((1+g)^2/(1-g)^2), 4 pi at g = 0.
        double g = gs[i];
        double want =
            g == 0.0 ? 4.0 * ST_PI : 2.0 * ST_PI * (1 - g) * (1 - g) / g * log((1 + g) / (1 - g));
        double got = sphere_integral(2, g);
        CHECK_REL(got, want, 1e-8, 0);
        CHECK(fabs(got - 1.0) > 0.1, "thesis HG g=%g integrates to %g, should not be normalized", g,
              got);
    }
    CHECK_REL(sphere_integral(1, 0), 1.0, 1e-12, 0);
    CHECK_REL(sphere_integral(4, 0), 1.0, 1e-12, 0);
    CHECK_REL(sphere_integral(3, 0), 4.0 * ST_PI / 3.0, 1e-12, 0); // cos^2: not normalized
    // Point values and conventions.
    CHECK_REL(st_phase_hg(0.3, 0.0), 1.0 / (4 * ST_PI), 1e-14, 0);
    CHECK_REL(st_phase_rayleigh(0.0), 3.0 / (16 * ST_PI), 1e-14, 0);
    CHECK_REL(st_phase_hg(1.0, 0.5), 0.75 / (4 * ST_PI * 0.125), 1e-14,
              0); // forward peak (1+g)/(1-g)^2/4pi
    CHECK(st_phase_hg(1.0, 0.5) > st_phase_hg(-1.0, 0.5), "g > 0 must favour cos = +1");
    CHECK(st_phase_hg(0.2, 1.5) == st_phase_hg(0.2, 0.999), "|g| clamps to 0.999");
    CHECK(st_phase_hg(0.2, -7) == st_phase_hg(0.2, -0.999), "|g| clamps to 0.999");
    CHECK(isfinite(st_phase_hg(1.0, 1.0)) && isfinite(st_phase_hg(1.0 + 1e-12, 0.999)),
          "finite at the clamp");
    CHECK_REL(st_phase_eval(ST_PHASE_HG, 0.4, 0.7), st_phase_hg(0.4, 0.7), 0, 0);
    CHECK_REL(st_phase_eval(ST_PHASE_RAYLEIGH, 0.4, 0.7), st_phase_rayleigh(0.4), 0, 0);
}

static void test_integrators(void) {
    const double exact = 2.0 * (1.0 - exp(-5.0)); // sigma_t 0.5, length 10, S 1
    CHECK_REL(exact, 1.986524, 1e-6, 0);
    for (int n = 1; n <= 64; n++)
        CHECK_REL(st_march_constant(ST_INTEGRATOR_ENERGY, 1.0, 0.5, 10.0, n), exact, 1e-12, 0);
    CHECK(fabs(st_march_constant(ST_INTEGRATOR_THESIS, 1.0, 0.5, 10.0, 4) - 3.480) < 5e-4,
          "thesis near: %.6f", st_march_constant(ST_INTEGRATOR_THESIS, 1.0, 0.5, 10.0, 4));
    CHECK(fabs(st_march_constant(ST_INTEGRATOR_THESIS_FAR, 1.0, 0.5, 10.0, 4) - 0.997) < 5e-4,
          "thesis far: %.6f", st_march_constant(ST_INTEGRATOR_THESIS_FAR, 1.0, 0.5, 10.0, 4));
    // The Riemann sums converge (first order) to the exact value.
    CHECK_REL(st_march_constant(ST_INTEGRATOR_THESIS, 1.0, 0.5, 10.0, 100000), exact, 1e-4, 0);
    CHECK_REL(st_march_constant(ST_INTEGRATOR_THESIS_FAR, 1.0, 0.5, 10.0, 100000), exact, 1e-4, 0);
    // The sigma_t -> 0 limit is S * length, continuous and without 0/0.
    CHECK_REL(st_march_constant(ST_INTEGRATOR_ENERGY, 2.0, 0.0, 10.0, 7), 20.0, 1e-14, 0);
    CHECK_REL(st_march_constant(ST_INTEGRATOR_ENERGY, 2.0, 1e-14, 10.0, 7), 20.0 * (1 - 0.5e-13),
              1e-14, 0);
    CHECK_REL(st_march_constant(ST_INTEGRATOR_ENERGY, 2.0, 1e-7, 10.0, 3),
              2.0 * -expm1(-1e-6) / 1e-7, 1e-13, 0);
    CHECK_REL(st_step_transfer(1e-10, 1.0), 1.0 - 0.5e-10, 1e-15, 0);
    // A dense medium saturates at S / sigma_t.
    CHECK_REL(st_march_constant(ST_INTEGRATOR_ENERGY, 3.0, 50.0, 10.0, 2), 3.0 / 50.0, 1e-14, 0);
    st_integrator it;
    CHECK(st_integrator_parse("thesis", &it) && it == ST_INTEGRATOR_THESIS, "parse thesis");
    CHECK(st_integrator_parse("energy", &it) && it == ST_INTEGRATOR_ENERGY, "parse energy");
    CHECK(!st_integrator_parse("riemann", &it), "unknown integrator name");
}

// A ray along +x from the origin, the light at distance D under angle gamma.
static st_inscatter_problem ray_problem(double D, double gamma, double s, double ss, double st) {
    st_inscatter_problem p = {{0, 0, 0}, {1, 0, 0}, s,  {D * cos(gamma), D * sin(gamma), 0},
                              2.5,       ss,        st, ST_PHASE_ISOTROPIC,
                              0};
    return p;
}

static void test_sun(void) {
    // Zero extinction: the atan form; here h = 1, a = -2, b = 8.
    st_inscatter_problem p0 = {{-2, 0, 0}, {1, 0, 0},          10, {0, 1, 0}, 3.0, 0.2,
                               0.0,        ST_PHASE_ISOTROPIC, 0};
    double atan_form = st_inscatter_atan(0.2, 3.0, 1.0, -2.0, 8.0);
    CHECK_REL(st_inscatter_quadrature(&p0, 100000), atan_form, 1e-9, 0);
    CHECK_REL(st_inscatter_sun_problem(&p0), atan_form, 1e-9, 0);
    CHECK_REL(atan_form, 0.2 * 3.0 / (4 * ST_PI) * (atan(8.0) + atan(2.0)), 1e-14, 0);

    // Sun et al. against brute force over geometries and densities.
    const struct {
        double D, gamma, s;
    } geo[] = {
        {2.0, 1.0, 10.0},          {1.0, ST_PI / 2, 4.0}, {5.0, 0.3, 3.0}, {3.0, 2.5, 6.0},
        {0.5, 0.2, 20.0},          {4.0, 0.01, 8.0}, // passes 4 cm from the light: sharp peak
        {3.0, 2e-3, 2.0},                            // just above the quadrature switch
        {12.0, 0.0, 10.0},                           // light straight ahead beyond the segment
        {2.0, ST_PI, 10.0},                          // light straight behind
        {12.0, 1e-9, 10.0},                          // sin(gamma) ~ 0
        {2.0, ST_PI - 1e-7, 10.0},                   // sin(gamma) ~ 0 behind
        {3.0, 5e-4, 2.9}, // below the switch, ray ends 0.1 before the light
    };
    const double sig[][2] = {{0.1, 0.1}, {0.05, 0.5}, {0.9, 1.0}, {0.3, 0.0 + 0.3}, {0.0, 2.0}};
    for (size_t i = 0; i < sizeof geo / sizeof geo[0]; i++)
        for (size_t k = 0; k < sizeof sig / sizeof sig[0]; k++) {
            st_inscatter_problem p =
                ray_problem(geo[i].D, geo[i].gamma, geo[i].s, sig[k][0], sig[k][1]);
            double sun = st_inscatter_sun(p.sigma_s, p.sigma_t, p.intensity, geo[i].D, geo[i].gamma,
                                          geo[i].s);
            double brute = st_inscatter_quadrature(&p, 100000);
            CHECK(isfinite(sun), "geometry %zu: non-finite", i);
            CHECK(fabs(sun - brute) <= 1e-4 * fabs(brute) + 1e-300,
                  "geometry %zu sigma %zu: sun %.10g brute %.10g", i, k, sun, brute);
            CHECK_REL(st_inscatter_sun_problem(&p), sun, 1e-8, 0);
        }
    // Continuity across the quadrature switch at sin(gamma) = 1e-3.
    double below = st_inscatter_sun(0.1, 0.2, 1.0, 4.0, 0.999e-3, 3.0);
    double above = st_inscatter_sun(0.1, 0.2, 1.0, 4.0, 1.001e-3, 3.0);
    CHECK_REL(below, above, 1e-5, 0);
    CHECK(isinf(st_inscatter_sun(0.1, 0.1, 1.0, 3.0, 0.0, 10.0)), "light on the segment diverges");
    // F(u, v) at known points: F(0, v) = v; F(u, pi/4) by direct reasoning
    // F(1, pi/4) = integral_0^1 e^(-t)/(1+t^2) dt (t = tan x) = 0.524797143260278.
    CHECK_REL(st_sun_F(0.0, 1.2), 1.2, 1e-15, 0);
    CHECK_REL(st_sun_F(1.0, ST_PI / 4), 0.524797143260278, 1e-9, 0);
}

static void test_form_factors(void) {
    CHECK(fabs(st_ff_perpendicular_rects(1, 1, 1) - 0.200044) < 1e-6,
          "perpendicular closed form %.9f", st_ff_perpendicular_rects(1, 1, 1));
    CHECK(fabs(st_ff_parallel_rects(1, 1, 1) - 0.199825) < 1e-6, "parallel closed form %.9f",
          st_ff_parallel_rects(1, 1, 1));
    // Numerically, from the geometry: floor [0,1]^2 (normal +y) to the wall x = 0.
    const double fc[3] = {0, 0, 0}, fu[3] = {0, 0, 1}, fv[3] = {1, 0, 0};
    const double wc[3] = {0, 0, 0}, wu[3] = {0, 1, 0}, wv[3] = {0, 0, 1};
    double perp = st_ff_parallelograms(fc, fu, fv, wc, wu, wv);
    CHECK(fabs(perp - 0.200044) < 1e-6, "perpendicular numeric %.9f", perp);
    const double tc[3] = {0, 1, 0}, tu[3] = {1, 0, 0}, tv[3] = {0, 0, 1}; // the ceiling at y = 1
    double par = st_ff_parallelograms(fc, fu, fv, tc, tu, tv);
    CHECK(fabs(par - 0.199825) < 1e-6, "parallel numeric %.9f", par);
    // Non-square cases: numeric and closed forms agree.
    const double wu2[3] = {0, 2, 0};
    CHECK_REL(st_ff_parallelograms(fc, fu, fv, wc, wu2, wv), st_ff_perpendicular_rects(1, 1, 2),
              1e-7, 0);
    const double tc2[3] = {0, 0.5, 0}, tu2[3] = {3, 0, 0};
    const double fv3[3] = {3, 0, 0};
    CHECK_REL(st_ff_parallelograms(fc, fu, fv3, tc2, tu2, tv), st_ff_parallel_rects(3, 1, 0.5),
              1e-7, 0);
    // A point under a coaxial disk, the disk as a 4096-gon of equal area.
    for (int i = 0; i < 3; i++) {
        double R = 0.5 + i, h = 1.0 + 0.7 * i;
        enum { N = 4096 };
        static double v[N][3];
        double r = R * sqrt(2 * ST_PI / (N * sin(2 * ST_PI / N))); // same area as the disk
        for (int k = 0; k < N; k++) {
            v[k][0] = r * cos(2 * ST_PI * k / N);
            v[k][1] = h;
            v[k][2] = r * sin(2 * ST_PI * k / N);
        }
        const double p[3] = {0, 0, 0}, n[3] = {0, 1, 0};
        double f = st_ff_point_polygon(p, n, (const double(*)[3])v, N);
        CHECK_REL(f, st_ff_point_disk(R, h), 1e-6, 0);
        CHECK_REL(st_ff_point_disk(R, h), R * R / (R * R + h * h), 1e-15, 0);
        // The bounded area kernel is the disk's form factor times pi.
        CHECK_REL(st_area_kernel(ST_PI * R * R, h * h) / ST_PI, st_ff_point_disk(R, h), 1e-14, 0);
    }
    // Far away the bounded kernel tends to a / d^2.
    CHECK_REL(st_area_kernel(1e-4, 4.0), 1e-4 / 4.0, 1e-5, 0);
    CHECK(isfinite(st_area_kernel(0.01, 0.0)) && fabs(st_area_kernel(0.01, 0.0) - ST_PI) < 1e-12,
          "bounded at d = 0");
}

int main(void) {
    test_phase();
    test_integrators();
    test_sun();
    test_form_factors();
    return st_test_summary("reference_physics");
}
