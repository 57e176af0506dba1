// One (or K) diffuse bounces in the reference against form factor oracles:
// a sender of constant radiance L0 = 1 gives the receiver L1 = rho F, F from
// Lambert's contour formula at each pixel's hit point; its area average is
// the published form factor. Also the thesis estimator's bias, occluders with
// and without bounce visibility, and a furnace for K bounces.
#include "ref_test_util.h"
#include "st_test_support.h"

static const double rho = 0.5;

// Where the view ray of pixel (i, j) meets the plane y = 0.
static void floor_point(const st_scene *s, int i, int j, double p[3]) {
    double d[3];
    contract_ray(s, i, j, d);
    double t = -s->camera.position[1] / d[1];
    for (int k = 0; k < 3; k++)
        p[k] = s->camera.position[k] + t * d[k];
}

typedef struct {
    double mean, oracle, se,
        z2; // image mean, oracle mean, standard error of the mean, mean z^2 per pixel
} stats;

// Compares the image (channel 0) with a per-pixel oracle.
static stats compare(const st_image *img, const double *oracle) {
    stats r = {0};
    int n = img->width * img->height;
    double se2 = 0;
    for (int j = 0; j < img->height; j++)
        for (int i = 0; i < img->width; i++) {
            const float *px = st_image_px(img, i, j);
            double o = oracle[j * img->width + i];
            r.mean += px[0];
            r.oracle += o;
            se2 += (double)px[3] * px[3];
            if (px[3] > 0) r.z2 += (px[0] - o) * (px[0] - o) / ((double)px[3] * px[3]);
        }
    r.mean /= n, r.oracle /= n, r.se = sqrt(se2) / n, r.z2 /= n;
    return r;
}

// Asserts the image mean matches the oracle mean within `rel` and within
// 4.5 standard errors, and that the per-pixel errors match the reported
// standard errors (mean z^2 ~ 1).
static void check_stats(const char *name, const stats *r, double rel) {
    double z = r->se > 0 ? fabs(r->mean - r->oracle) / r->se : 0;
    fprintf(
        stderr,
        "  %s: mean %.6f, oracle %.6f (rel %+.2e), stderr of mean %.1e (z %.2f), mean z^2 %.2f\n",
        name, r->mean, r->oracle, r->mean / r->oracle - 1, r->se, z, r->z2);
    CHECK(fabs(r->mean - r->oracle) <= rel * r->oracle, "%s: mean %.6g vs oracle %.6g", name,
          r->mean, r->oracle);
    CHECK(z < 4.5, "%s: %.2f standard errors off", name, z);
    CHECK(r->se == 0 || (r->z2 > 0.6 && r->z2 < 1.6),
          "%s: mean z^2 = %.3g, stderr channel inconsistent", name, r->z2);
}

// A camera straight above the unit square [0,1]^2 of y = 0 at height H whose
// view is exactly that square: pixel centres form a midpoint grid over it,
// so the image mean is an area average.
static void square_camera(st_scene *s, int n, double H) {
    const double pos[3] = {0.5, H, 0.5}, tgt[3] = {0.5, 0, 0.5}, up[3] = {0, 0, -1};
    scene_init(s, n, n, pos, tgt, up, 2.0 * atan(0.5 / H) * 180.0 / ST_PI, 100);
}

static const double floor_c[3] = {0, 0, 0}, floor_u[3] = {0, 0, 1},
                    floor_v[3] = {1, 0, 0}; // faces +y

static double point_ff(const double p[3], const double c[3], const double u[3], const double v[3]) {
    double q[4][3];
    for (int k = 0; k < 3; k++) {
        q[0][k] = c[k], q[1][k] = c[k] + u[k], q[2][k] = c[k] + u[k] + v[k], q[3][k] = c[k] + v[k];
    }
    const double n[3] = {0, 1, 0};
    return st_ff_point_polygon(p, n, (const double(*)[3])q, 4);
}

// integral over the wall x = 0, [0,1]^2 of cos(theta_x) dA for x = (p, 0, z)
// on the floor: the thesis estimator's expectation (inner integral in closed
// form: integral q / sqrt(a^2 + w^2) dw = q asinh(w / a)).
typedef struct {
    double p, z;
} thesis_ctx;
static double thesis_inner(double q, void *vc) {
    const thesis_ctx *c = vc;
    double a = sqrt(c->p * c->p + q * q);
    return q * (asinh((1.0 - c->z) / a) + asinh(c->z / a));
}

static void shared_edge(void) {
    const int N = 48;
    st_scene s;
    square_camera(&s, N, 0.9);
    add_quad(&s, floor_c, floor_u, floor_v, rho, 0);
    const double wc[3] = {0, 0, 0}, wu[3] = {0, 1, 0},
                 wv[3] = {0, 0, 1}; // the wall x = 0, faces +x
    add_quad(&s, wc, wu, wv, 0.0, 1.0);
    double *ff = malloc(sizeof(double) * N * N), *th = malloc(sizeof(double) * N * N);
    double grid = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double p[3];
            floor_point(&s, i, j, p);
            ff[j * N + i] = rho * point_ff(p, wc, wu, wv);
            grid += ff[j * N + i] / rho / (N * N);
            thesis_ctx c = {p[0], p[2]};
            th[j * N + i] = rho * st_integrate(thesis_inner, &c, 0.0, 1.0, 1e-12, 1e-10);
        }
    // The pixel grid samples the area average well enough to show the published number.
    fprintf(
        stderr,
        "  shared edge: pixel-grid average of the point form factor %.6f (closed form 0.200044)\n",
        grid);
    CHECK_REL(grid, 0.200044, 2e-3, 0);
    const struct {
        const char *name;
        st_ref_options o;
        double *oracle;
    } runs[] = {
        {"shared edge, visibility on",
         {.spp = 1024, .aov = ST_REF_INDIRECT, .bounces = 1, .seed = 1},
         ff},
        {"shared edge, visibility off",
         {.spp = 512, .aov = ST_REF_INDIRECT, .bounces = 1, .seed = 2, .no_visibility = true},
         ff},
        {"shared edge, thesis estimator",
         {.spp = 256,
          .aov = ST_REF_INDIRECT,
          .bounces = 1,
          .seed = 3,
          .estimator = ST_REF_EST_THESIS},
         th},
    };
    double means[3] = {0};
    for (int k = 0; k < 3; k++) {
        st_image img;
        if (!render(&s, &runs[k].o, &img)) continue;
        stats r = compare(&img, runs[k].oracle);
        check_stats(runs[k].name, &r, 0.01);
        means[k] = r.mean;
        st_image_free(&img);
    }
    // docs/physics.md: the thesis estimator is 2.8x too bright here.
    fprintf(stderr, "  thesis / true: %.3f\n", means[2] / means[0]);
    CHECK(fabs(means[2] / means[0] - 2.82) < 0.03, "thesis estimator ratio %.3f, expected 2.82",
          means[2] / means[0]);
    free(ff);
    free(th);
    st_scene_free(&s);
}

// Opposed parallel unit squares at distance 1, then with an opaque plate
// between them: visibility on removes the bounce, off keeps it.
static void parallel(void) {
    const int N = 48;
    const double cc[3] = {0, 1, 0}, cu[3] = {1, 0, 0}, cv[3] = {0, 0, 1}; // the ceiling, faces -y
    for (int blocked = 0; blocked < 2; blocked++) {
        st_scene s;
        square_camera(&s, N, blocked ? 0.4 : 0.9); // below the plate at y = 0.5
        add_quad(&s, floor_c, floor_u, floor_v, rho, 0);
        add_quad(&s, cc, cu, cv, 0.0, 1.0);
        if (blocked) // faces +y; lit by nothing at bounce 1, so L0 = 0
            add_quad(&s, (double[]){-1, 0.5, -1}, (double[]){0, 0, 3}, (double[]){3, 0, 0}, 0.5, 0);
        double *ff = malloc(sizeof(double) * N * N), *zero = calloc(N * N, sizeof(double)),
               grid = 0;
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                double p[3];
                floor_point(&s, i, j, p);
                ff[j * N + i] = rho * point_ff(p, cc, cu, cv);
                grid += ff[j * N + i] / rho / (N * N);
            }
        if (!blocked) {
            fprintf(stderr,
                    "  parallel: pixel-grid average of the point form factor %.6f (closed form "
                    "0.199825)\n",
                    grid);
            CHECK_REL(grid, 0.199825, 2e-3, 0);
        }
        st_ref_options on = {.spp = 1024, .aov = ST_REF_INDIRECT, .bounces = 1, .seed = 4};
        st_ref_options off = {
            .spp = 256, .aov = ST_REF_INDIRECT, .bounces = 1, .seed = 5, .no_visibility = true};
        st_image img;
        if (render(&s, &on, &img)) {
            stats r = compare(&img, blocked ? zero : ff);
            if (blocked) {
                fprintf(stderr, "  parallel, blocked, visibility on: mean %.3g\n", r.mean);
                CHECK(r.mean == 0.0,
                      "an opaque plate must remove the bounce with visibility on (mean %g)",
                      r.mean);
            } else {
                check_stats("parallel, visibility on", &r, 0.01);
            }
            st_image_free(&img);
        }
        if (render(&s, &off, &img)) {
            stats r = compare(&img, ff);
            check_stats(blocked ? "parallel, blocked, visibility off" : "parallel, visibility off",
                        &r, 0.01);
            st_image_free(&img);
        }
        free(ff);
        free(zero);
        st_scene_free(&s);
    }
}

// e^(-sigma_t d) / d^3: the coaxial disk's kernel in a medium (ctx: sigma_t).
static double disk_kernel(double d, void *ctx) {
    return exp(-*(double *)ctx * d) / (d * d * d);
}

// A point under a coaxial disk (an area-matched 256-gon) of radius R at
// height h: F = R^2 / (R^2 + h^2). One pixel looks at the point.
static void disk(void) {
    const double R = 0.8, h = 1.0;
    enum { NS = 256 };
    const double pos[3] = {0, 0.5, 0}, tgt[3] = {0, 0, 0}, up[3] = {0, 0, -1};
    st_scene s;
    scene_init(&s, 1, 1, pos, tgt, up, 10, 100);
    add_quad(&s, (double[]){-0.01, 0, -0.01}, (double[]){0, 0, 0.02}, (double[]){0.02, 0, 0}, rho,
             0);
    static double poly[NS][3];
    st_err err = {0};
    CHECK(st_test_add_disk(&s, NS, R, h, poly, &err), "add disk: %s", err.msg);
    const double p0[3] = {0, 0, 0}, n0[3] = {0, 1, 0};
    double F = st_ff_point_polygon(p0, n0, (const double(*)[3])poly, NS);
    CHECK_REL(F, st_ff_point_disk(R, h), 1e-4, 0);
    for (int vis = 0; vis < 2; vis++) {
        st_ref_options o = {.spp = vis ? 1000000 : 200000,
                            .aov = ST_REF_INDIRECT,
                            .bounces = 1,
                            .seed = 6,
                            .no_visibility = !vis};
        st_image img;
        if (!render(&s, &o, &img)) continue;
        double oracle = rho * F;
        stats r = compare(&img, &oracle);
        r.z2 = 1; // one pixel: its z^2 is a single draw, checked through z instead
        check_stats(vis ? "disk, visibility on" : "disk, visibility off", &r, 0.005);
        st_image_free(&img);
    }
    // In an absorbing medium the bounce's path is attenuated: with d^2 = h^2 +
    // r^2, L1 = rho 2 h^2 integral_h^sqrt(h^2 + R^2) e^(-sigma_t d) / d^3 dd.
    double sigma_a = 0.7;
    set_medium(&s, 0.0, sigma_a, ST_PHASE_ISOTROPIC, 0);
    double oracle =
        rho * 2 * h * h * st_integrate(disk_kernel, &sigma_a, h, sqrt(h * h + R * R), 1e-14, 1e-12);
    CHECK(oracle < 0.8 * rho * F, "the medium matters: %g vs %g", oracle, rho * F);
    for (int vis = 0; vis < 2; vis++) {
        st_ref_options o = {.spp = vis ? 1000000 : 200000,
                            .aov = ST_REF_INDIRECT,
                            .bounces = 1,
                            .seed = 7,
                            .no_visibility = !vis};
        st_image img;
        if (!render(&s, &o, &img)) continue;
        stats r = compare(&img, &oracle);
        r.z2 = 1;
        check_stats(vis ? "disk in medium, visibility on" : "disk in medium, visibility off", &r,
                    0.005);
        st_image_free(&img);
    }
    st_scene_free(&s);
}

// A closed box whose every face emits L = 1 with albedo rho: after K bounces
// the radiance is 1 + rho + ... + rho^K everywhere (a furnace test).
static void furnace(void) {
    const double pos[3] = {0.1, 0.2, 0.3}, tgt[3] = {-0.6, -0.4, -1}, up[3] = {0, 1, 0};
    st_scene s;
    scene_init(&s, 24, 24, pos, tgt, up, 90, 100);
    st_mesh m;
    const float mn[3] = {-1, -1, -1}, mx[3] = {1, 1, 1};
    st_mesh_box(&m, mn, mx, true);
    v3(m.albedo, rho, rho, rho);
    v3(m.emission, 1, 1, 1);
    st_err err = {0};
    CHECK(st_scene_add_mesh(&s, &m, &err), "add box");
    for (int K = 1; K <= 3; K++) {
        double want = 0;
        for (int k = 0; k <= K; k++)
            want += pow(rho, k);
        for (int vis = 0; vis < 2; vis++) {
            st_ref_options o = {.spp = vis ? 2 : 256,
                                .aov = ST_REF_COMBINED,
                                .bounces = K,
                                .seed = 8,
                                .no_visibility = !vis};
            st_image img;
            if (!render(&s, &o, &img)) continue;
            double *oracle = malloc(sizeof(double) * 24 * 24);
            for (int k = 0; k < 24 * 24; k++)
                oracle[k] = want;
            stats r = compare(&img, oracle);
            char name[64];
            snprintf(name, sizeof name, "furnace K=%d, visibility %s", K, vis ? "on" : "off");
            if (vis) { // every path returns exactly the same value: no noise
                fprintf(stderr, "  %s: mean %.7f, expected %.7f\n", name, r.mean, want);
                CHECK_REL(r.mean, want, 1e-6, 0);
                CHECK(r.se == 0, "%s: noise where there should be none", name);
            } else {
                check_stats(name, &r, 0.005);
            }
            free(oracle);
            st_image_free(&img);
        }
    }
    st_scene_free(&s);
}

int main(void) {
    shared_edge();
    parallel();
    disk();
    furnace();
    return st_test_summary("reference_indirect");
}
