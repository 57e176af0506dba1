// Heterogeneous media (medium.density): the optical-depth model of
// st_physics.c against quadrature and analytic answers, the reference's
// ratio tracking against those closed forms, an OpenVDB box of constant
// density, the scene validation and the GPU path's refusal.
#include "ref_test_util.h"
#include "vdb_writer.h"

// ---- the model ---------------------------------------------------------------

typedef struct {
    const st_density_desc *d;
    double o[3], w[3];
} line_ctx;

static double density_on_line(double t, void *p) {
    const line_ctx *c = p;
    double x[3] = {c->o[0] + t * c->w[0], c->o[1] + t * c->w[1], c->o[2] + t * c->w[2]};
    return st_density_at(c->d, x);
}

static void unit(double w[3]) {
    double l = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; k++)
        w[k] /= l;
}

// Height fog's closed form against adaptive Gauss-Kronrod of e^(-k (y - y0))
// along the ray: horizontal, vertical both ways, oblique, almost horizontal,
// and falloffs down to 0.
static void height_closed_form(void) {
    const double dirs[][3] = {{1, 0, 0},        {0, 1, 0},    {0, -1, 0},     {1, 0.3, 0.2},
                              {0.2, -0.7, 0.4}, {1, 1e-9, 0}, {-0.3, 1e-5, 1}};
    const double falloffs[] = {0.8, 5.0, 1e-3, 1e-9, 1e-14, 0.0};
    const double starts[] = {-1.0, 0.5, 3.0}, lengths[] = {0.5, 10.0};
    int n = 0;
    double worst = 0;
    for (size_t a = 0; a < sizeof dirs / sizeof dirs[0]; a++)
        for (size_t b = 0; b < sizeof falloffs / sizeof falloffs[0]; b++)
            for (size_t c = 0; c < 3; c++)
                for (size_t e = 0; e < 2; e++) {
                    st_density_desc d = {
                        .kind = ST_DENSITY_HEIGHT, .base = 0.3, .falloff = falloffs[b]};
                    line_ctx lc = {
                        &d, {0.4, starts[c], -0.2}, {dirs[a][0], dirs[a][1], dirs[a][2]}};
                    unit(lc.w);
                    double L = lengths[e];
                    double want = st_integrate(density_on_line, &lc, 0.0, L, 0.0, 1e-13);
                    double got = st_density_integral(&d, lc.o, lc.w, 0.0, L);
                    double err = fabs(got - want) / want;
                    worst = fmax(worst, err);
                    CHECK(err < 1e-10 && isfinite(got),
                          "height fog k %g, y %g, dir %zu, L %g: %.15g vs quadrature %.15g",
                          d.falloff, starts[c], a, L, got, want);
                    // A sub-segment [t0, t1] equals the difference of the prefixes.
                    double mid = st_density_integral(&d, lc.o, lc.w, 0.25 * L, L) +
                                 st_density_integral(&d, lc.o, lc.w, 0.0, 0.25 * L);
                    CHECK_REL(mid, got, 1e-12, 0);
                    n++;
                }
    fprintf(stderr, "  height fog closed form: %d segments, worst rel error %.2e\n", n, worst);
    // Limits written out: horizontal = d(y) L exactly; falloff 0 = L.
    st_density_desc d = {.kind = ST_DENSITY_HEIGHT, .base = 1.0, .falloff = 0.5};
    CHECK_REL(st_height_fog_integral(1.0, 0.5, 3.0, 0.0, 4.0), 4.0 * exp(-1.0), 1e-15, 0);
    CHECK_REL(st_height_fog_integral(1.0, 0.0, 3.0, -0.6, 4.0), 4.0, 1e-15, 0);
    // Straight down from y = 3 to y = 1 at k = 0.5: integral_1^3 e^(-0.5 (y - 1)) dy = 2 (1 -
    // e^-1).
    CHECK_REL(st_height_fog_integral(1.0, 0.5, 3.0, -1.0, 2.0), 2.0 * (1.0 - exp(-1.0)), 1e-14, 0);
    // Far below the base in steep fog: huge but finite, never NaN.
    double deep = st_height_fog_integral(0.0, 50.0, -10.0, -1.0, 100.0);
    CHECK(deep > 0 && !isnan(deep), "deep fog integral %g", deep);
    double T[3], sig[3] = {0.1, 0.0, 0.2};
    const double o[3] = {0, -10, 0}, w[3] = {0, -1, 0};
    st_density_desc steep = {.kind = ST_DENSITY_HEIGHT, .base = 0.0, .falloff = 50.0};
    st_segment_transmittance(sig, &steep, o, w, 0.0, 100.0, T);
    CHECK(T[0] == 0.0 && T[1] == 1.0 && T[2] == 0.0, "steep fog T = %g %g %g", T[0], T[1], T[2]);
    // The majorant bounds the density on the segment: at the lower end.
    const double o2[3] = {0, 2, 0}, w2[3] = {0.6, -0.8, 0};
    CHECK_REL(st_density_majorant(&d, o2, w2, 0.0, 2.0), exp(-0.5 * (0.4 - 1.0)), 1e-15, 0);
}

// A grid built by hand: random voxels, a rotated, scaled, shifted placement.
static st_density_grid *hand_grid(void) {
    st_density_grid *g = calloc(1, sizeof *g);
    g->n[0] = 6, g->n[1] = 5, g->n[2] = 7;
    g->lo[0] = -3, g->lo[1] = 2, g->lo[2] = 0;
    g->values = calloc(6 * 5 * 7, sizeof(float));
    uint64_t s = 12345;
    for (int k = 1; k < 6; k++)
        for (int j = 1; j < 4; j++)
            for (int i = 1; i < 5; i++) {
                s = s * 6364136223846793005ull + 1442695040888963407ull;
                float v = (float)((s >> 40) / (double)(1ull << 24)) * 3.0f;
                g->values[(k * 5 + j) * 6 + i] = v;
                g->max_value = fmax(g->max_value, v);
            }
    // world = R S i + t, R a rotation about (1, 1, 0) by 30 degrees.
    double ax[3] = {1 / sqrt(2.0), 1 / sqrt(2.0), 0}, c = cos(0.5236), sn = sin(0.5236);
    double R[3][3], S[3] = {0.3, 0.2, 0.25}, t[3] = {0.5, -1.0, 0.2};
    for (int r = 0; r < 3; r++)
        for (int q = 0; q < 3; q++) {
            double cross = 0;
            if (r != q) {
                int o = 3 - r - q;
                cross = ((r + 1) % 3 == q ? -1.0 : 1.0) * ax[o];
            }
            R[r][q] = (r == q ? c : 0) + (1 - c) * ax[r] * ax[q] + sn * cross;
        }
    for (int r = 0; r < 3; r++) {
        for (int q = 0; q < 3; q++) {
            g->to_world[4 * r + q] = R[r][q] * S[q];
            g->to_index[4 * q + r] = R[r][q] / S[q]; // (R S)^-1 = S^-1 R^T
        }
        g->to_world[4 * r + 3] = t[r];
    }
    for (int q = 0; q < 3; q++)
        g->to_index[4 * q + 3] = -(g->to_index[4 * q] * t[0] + g->to_index[4 * q + 1] * t[1] +
                                   g->to_index[4 * q + 2] * t[2]);
    return g;
}

// The DDA with 2-point Gauss per cell against adaptive quadrature of the
// trilinear density, on random segments through a rotated grid.
static void grid_integral(void) {
    st_density_grid *g = hand_grid();
    st_density_desc d = {.kind = ST_DENSITY_GRID, .grid = g};
    // Voxel centres reproduce the voxel values.
    double x[3], p[3] = {-3 + 2, 2 + 3, 0 + 4};
    for (int r = 0; r < 3; r++)
        x[r] = g->to_world[4 * r] * p[0] + g->to_world[4 * r + 1] * p[1] +
               g->to_world[4 * r + 2] * p[2] + g->to_world[4 * r + 3];
    CHECK_REL(st_density_at(&d, x), g->values[(4 * 5 + 3) * 6 + 2], 1e-12, 1e-12);
    uint64_t s = 99;
    double worst = 0;
    int n = 0, above = 0;
    for (int k = 0; k < 40; k++) {
        // From a random point toward a random point of the block (index space).
        line_ctx lc = {&d, {0, 0, 0}, {0, 0, 0}};
        double aim[3], u[3];
        for (int r = 0; r < 3; r++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            lc.o[r] = -2.0 + 4.0 * ((s >> 11) / (double)(1ull << 53));
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            u[r] = g->lo[r] + (g->n[r] - 1) * ((s >> 11) / (double)(1ull << 53));
        }
        for (int r = 0; r < 3; r++)
            aim[r] = g->to_world[4 * r] * u[0] + g->to_world[4 * r + 1] * u[1] +
                     g->to_world[4 * r + 2] * u[2] + g->to_world[4 * r + 3];
        for (int r = 0; r < 3; r++)
            lc.w[r] = aim[r] - lc.o[r];
        if (k == 0) lc.w[0] = 1, lc.w[1] = lc.w[2] = 0, lc.o[1] = aim[1], lc.o[2] = aim[2];
        unit(lc.w);
        // Adaptive Gauss-Kronrod over 1 mm pieces: the trilinear density has
        // kinks at every cell face, which one adaptive call resolves poorly.
        double want = 0;
        for (int q = 0; q < 4000; q++)
            want += st_integrate(density_on_line, &lc, q * 1e-3, (q + 1) * 1e-3, 1e-16, 1e-13);
        double got = st_density_integral(&d, lc.o, lc.w, 0.0, 4.0);
        if (want > 0) n++;
        worst = fmax(worst, fabs(got - want) / fmax(want, 1e-3));
        CHECK(fabs(got - want) <= 1e-9 * want + 1e-11,
              "grid segment %d: DDA %.15g, quadrature %.15g", k, got, want);
        for (int q = 0; q < 16; q++) { // the majorant bounds every point of the segment
            double t = 4.0 * q / 15.0,
                   y[3] = {lc.o[0] + t * lc.w[0], lc.o[1] + t * lc.w[1], lc.o[2] + t * lc.w[2]};
            above += st_density_at(&d, y) > st_density_majorant(&d, lc.o, lc.w, 0, 4.0);
        }
    }
    fprintf(stderr, "  grid DDA: %d segments through the grid, worst rel error %.2e\n", n, worst);
    CHECK(n >= 30, "only %d of 40 segments cross the grid", n);
    CHECK(above == 0, "%d points above the majorant", above);
    st_density_grid_free(g);
    free(g);
}

// ---- the reference -----------------------------------------------------------

static double tau_height(const st_density_desc *d, const double o[3], const double w[3], double L) {
    return st_density_integral(d, o, w, 0.0, L);
}

// Pixel values against the oracle: each within 5 standard errors (plus a
// rounding allowance), and the mean z^2 consistent with the stderr.
static void check_z(const char *name, const st_image *img, const double *want) {
    int n = 0, bad = 0;
    double z2 = 0, zsum = 0, worst = 0;
    for (int j = 0; j < img->height; j++)
        for (int i = 0; i < img->width; i++) {
            const float *px = st_image_px(img, i, j);
            double w = want[j * img->width + i], e = fabs(px[0] - w);
            worst = fmax(worst, e / fmax(w, 1e-9));
            bad += !(e <= 5.0 * px[3] + 1e-5 * w + 1e-9) || !isfinite(px[0]);
            if (px[3] > 0) z2 += e * e / ((double)px[3] * px[3]), zsum += (px[0] - w) / px[3], n++;
        }
    fprintf(stderr, "  %s: worst rel error %.2e, mean z %.3f, mean z^2 %.2f over %d noisy pixels\n",
            name, worst, n ? zsum / n : 0.0, n ? z2 / n : 0.0, n);
    // A bias shows as a mean z away from 0 (its standard error is 1/sqrt(n)).
    CHECK(n > 0 && fabs(zsum / n) < 4.0 / sqrt(n), "%s: mean z %.3g over %d pixels: biased", name,
          n ? zsum / n : 0.0, n);
    CHECK(bad == 0, "%s: %d pixels off by more than 5 standard errors", name, bad);
    CHECK(n > 0 && z2 / n < 3.0, "%s: mean z^2 %.3g: stderr does not describe the error", name,
          n ? z2 / n : 0.0);
}

// An emitter (radiance 1, albedo 0.5) behind height fog, lit by a point light:
// pixel = (1 + rho/pi I cos / d^2 e^(-sigma_t tau(p -> light))) e^(-sigma_t tau(view)),
// both optical depths from the closed form; the reference tracks them.
static void emitter_through_height_fog(void) {
    const double cam[3] = {0, 0.5, 4}, tgt[3] = {0, 1.5, 0}, up[3] = {0, 1, 0};
    const double lp[3] = {0.5, 3.0, 2.0}, I = 6.0, sig_a = 0.6;
    st_scene s;
    scene_init(&s, 17, 17, cam, tgt, up, 50, 50);
    add_quad(&s, (double[]){-6, -4, 0}, (double[]){12, 0, 0}, (double[]){0, 12, 0}, 0.5, 1.0);
    add_light(&s, lp, I);
    set_medium(&s, 0.0, sig_a, ST_PHASE_ISOTROPIC, 0);
    s.density = (st_density_desc){.kind = ST_DENSITY_HEIGHT, .base = 0.5, .falloff = 0.9};
    double *want = calloc(17 * 17, sizeof *want);
    double tmin = 1;
    for (int j = 0; j < 17; j++)
        for (int i = 0; i < 17; i++) {
            double d[3];
            contract_ray(&s, i, j, d);
            double t = -cam[2] / d[2], p[3] = {cam[0] + t * d[0], cam[1] + t * d[1], 0};
            double v[3] = {lp[0] - p[0], lp[1] - p[1], lp[2] - p[2]};
            double dl = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            for (int k = 0; k < 3; k++)
                v[k] /= dl;
            double Tl = exp(-sig_a * tau_height(&s.density, p, v, dl));
            double Tv = exp(-sig_a * tau_height(&s.density, cam, d, t));
            want[j * 17 + i] = (1.0 + 0.5 / ST_PI * I * v[2] / (dl * dl) * Tl) * Tv;
            tmin = fmin(tmin, Tv);
        }
    CHECK(tmin < 0.2, "the fog must matter: smallest view transmittance %g", tmin);
    st_ref_options o = {.spp = 256, .aov = ST_REF_COMBINED, .seed = 5};
    st_image img;
    if (render(&s, &o, &img)) {
        check_z("emitter through height fog", &img, want);
        st_image_free(&img);
    }
    free(want);
    st_scene_free(&s);
}

typedef struct {
    const st_scene *s;
    double d[3];
} scatter_ctx;

// The single-scattering integrand with closed-form optical depths.
static double scatter_integrand(double t, void *p) {
    const scatter_ctx *c = p;
    const st_scene *s = c->s;
    const double *cam =
        (const double[]){s->camera.position[0], s->camera.position[1], s->camera.position[2]};
    double x[3] = {cam[0] + t * c->d[0], cam[1] + t * c->d[1], cam[2] + t * c->d[2]};
    const float *lp = s->lights[0].position;
    double v[3] = {lp[0] - x[0], lp[1] - x[1], lp[2] - x[2]};
    double d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2], dl = sqrt(d2);
    for (int k = 0; k < 3; k++)
        v[k] /= dl;
    double st = (double)s->medium.sigma_s[0] + s->medium.sigma_a[0];
    double tau = tau_height(&s->density, cam, c->d, t) + tau_height(&s->density, x, v, dl);
    double ph = st_phase_eval(s->medium.phase, v[0] * c->d[0] + v[1] * c->d[1] + v[2] * c->d[2],
                              s->medium.g);
    return exp(-st * tau) * s->medium.sigma_s[0] * st_density_at(&s->density, x) * ph *
           s->lights[0].intensity[0] / d2;
}

// In-scattering from a point light in height fog (no surfaces, so no
// shadows) against a 1D quadrature of the single-scattering integral.
static void inscatter_height_fog(st_phase_kind phase, double g, const char *name) {
    const double cam[3] = {0, 0.3, 2}, tgt[3] = {0, 1, -3}, up[3] = {0, 1, 0};
    const double lp[3] = {0.5, 1.2, -2}, far_z = 12;
    st_scene s;
    scene_init(&s, 11, 11, cam, tgt, up, 50, far_z);
    add_light(&s, lp, 5.0);
    set_medium(&s, 0.15, 0.05, phase, g);
    s.density = (st_density_desc){.kind = ST_DENSITY_HEIGHT, .base = 0.0, .falloff = 0.6};
    double want[121], f[3];
    for (int k = 0; k < 3; k++)
        f[k] = tgt[k] - cam[k];
    unit(f);
    for (int j = 0; j < 11; j++)
        for (int i = 0; i < 11; i++) {
            scatter_ctx c = {&s, {0, 0, 0}};
            contract_ray(&s, i, j, c.d);
            double len = far_z / (c.d[0] * f[0] + c.d[1] * f[1] + c.d[2] * f[2]);
            want[j * 11 + i] = st_integrate(scatter_integrand, &c, 0.0, len, 0.0, 1e-10);
        }
    st_ref_options o = {.spp = 32, .aov = ST_REF_INSCATTER, .seed = 11, .march_steps = 64};
    st_image img;
    if (render(&s, &o, &img)) {
        check_z(name, &img, want);
        st_image_free(&img);
    }
    st_scene_free(&s);
}

typedef struct {
    const st_scene *s;
    double d[3], L[3], entry;
} sun_ctx;

// The same integrand for a directional light: irradiance E, its path through
// the medium from x toward it of length max(0, entry - dot(x, L)).
static double sun_integrand(double t, void *p) {
    const sun_ctx *c = p;
    const st_scene *s = c->s;
    const float *cp = s->camera.position;
    const double cam[3] = {cp[0], cp[1], cp[2]};
    double x[3] = {cam[0] + t * c->d[0], cam[1] + t * c->d[1], cam[2] + t * c->d[2]};
    double path = fmax(0.0, c->entry - (x[0] * c->L[0] + x[1] * c->L[1] + x[2] * c->L[2]));
    double st = (double)s->medium.sigma_s[0] + s->medium.sigma_a[0];
    double tau = tau_height(&s->density, cam, c->d, t) + tau_height(&s->density, x, c->L, path);
    double ph = st_phase_eval(
        s->medium.phase, c->L[0] * c->d[0] + c->L[1] * c->d[1] + c->L[2] * c->d[2], s->medium.g);
    return exp(-st * tau) * s->medium.sigma_s[0] * st_density_at(&s->density, x) * ph *
           s->lights[0].intensity[0];
}

// A sun in height fog: strata uniform in t, and each point's light path to
// the plane where the sun enters the medium (two tiny quads far out of view
// set the scene's bounds, and so that plane).
static void inscatter_height_fog_sun(void) {
    const double cam[3] = {0, 0.3, 2}, tgt[3] = {0, 1, -3}, up[3] = {0, 1, 0}, far_z = 12;
    st_scene s;
    scene_init(&s, 11, 11, cam, tgt, up, 50, far_z);
    add_quad(&s, (double[]){-20, 5, -20}, (double[]){0.1, 0, 0}, (double[]){0, 0, 0.1}, 0.5, 0);
    add_quad(&s, (double[]){20, -1, 20}, (double[]){0.1, 0, 0}, (double[]){0, 0, 0.1}, 0.5, 0);
    st_light_desc l = {.type = ST_LIGHT_DIRECTIONAL};
    double dir[3] = {0.3, -1, 0.2};
    unit(dir);
    v3(l.direction, dir[0], dir[1], dir[2]);
    v3(l.intensity, 2, 2, 2);
    st_err err = {0};
    if (!st_scene_add_light(&s, &l, &err)) exit(1);
    set_medium(&s, 0.15, 0.05, ST_PHASE_HG, 0.4);
    s.density = (st_density_desc){.kind = ST_DENSITY_HEIGHT, .base = 0.0, .falloff = 0.6};
    sun_ctx c = {&s,
                 {0, 0, 0},
                 {-s.lights[0].direction[0], -s.lights[0].direction[1], -s.lights[0].direction[2]},
                 st_directional_entry(&s, s.lights[0].direction)};
    double want[121], f[3], minpath = INFINITY;
    for (int k = 0; k < 3; k++)
        f[k] = tgt[k] - cam[k];
    unit(f);
    for (int j = 0; j < 11; j++)
        for (int i = 0; i < 11; i++) {
            contract_ray(&s, i, j, c.d);
            double len = far_z / (c.d[0] * f[0] + c.d[1] * f[1] + c.d[2] * f[2]);
            want[j * 11 + i] = st_integrate(sun_integrand, &c, 0.0, len, 0.0, 1e-10);
            double xe[3] = {cam[0] + len * c.d[0], cam[1] + len * c.d[1], cam[2] + len * c.d[2]};
            minpath = fmin(minpath, c.entry - (xe[0] * c.L[0] + xe[1] * c.L[1] + xe[2] * c.L[2]));
        }
    CHECK(minpath > 3.0, "the sun's paths through the fog must be long here: %g", minpath);
    st_ref_options o = {.spp = 32, .aov = ST_REF_INSCATTER, .seed = 13, .march_steps = 64};
    st_image img;
    if (render(&s, &o, &img)) {
        check_z("in-scattering of a sun in height fog", &img, want);
        st_image_free(&img);
    }
    st_scene_free(&s);
}

// The constant-density box from an OpenVDB file: 10^3 voxels of density 2 at
// voxel size 0.1, scaled by 2 and moved to the origin. The trilinear density
// is 2 on [-0.9, 0.9]^3 and falls linearly to 0 over one voxel (0.2 m) on each
// side, so a ray along an axis through the plateau has tau = 2 * 10 * 0.2 =
// 4 exactly, and a ray missing [-1.1, 1.1]^3 has tau = 0.
static void vdb_box(const char *dir) {
    char path[1024];
    snprintf(path, sizeof path, "%s/box.vdb", dir);
    st_test_vdb spec = {.name = "density", .n = {10, 10, 10}, .value = 2.0f, .voxel = 0.1};
    CHECK(st_test_write_vdb(path, &spec), "writing %s", path);
    st_density_grid *g = calloc(1, sizeof *g);
    st_err err = {0};
    const double tr[3] = {-0.9, -0.9, -0.9}, sc[3] = {2, 2, 2};
    if (!st_vdb_load(path, "density", tr, sc, g, &err)) {
        CHECK(0, "st_vdb_load: %s", err.msg);
        free(g);
        return;
    }
    CHECK(g->n[0] == 12 && g->n[1] == 12 && g->n[2] == 12, "block %d %d %d", g->n[0], g->n[1],
          g->n[2]);
    CHECK_REL(g->max_value, 2.0, 0, 0);
    CHECK_REL(g->bmin[0], -1.1, 1e-12, 1e-12);
    CHECK_REL(g->bmax[2], 1.1, 1e-12, 1e-12);
    st_density_desc d = {.kind = ST_DENSITY_GRID, .grid = g};
    const double o[3] = {0.13, -0.31, -5}, w[3] = {0, 0, 1}, ox[3] = {-5, 0.8, 0.4},
                 wx[3] = {1, 0, 0}, miss[3] = {1.15, 0, -5};
    CHECK_REL(st_density_integral(&d, o, w, 0.0, 10.0), 4.0, 1e-13, 0);
    CHECK_REL(st_density_integral(&d, ox, wx, 0.0, 10.0), 4.0, 1e-13, 0);
    CHECK_REL(st_density_integral(&d, o, w, 0.0, 5.0), 2.0, 1e-13, 0); // to the centre
    CHECK(st_density_integral(&d, miss, w, 0.0, 10.0) == 0.0, "a ray beside the box");
    const double centre[3] = {0.3, -0.2, 0.5}, ramp[3] = {1.0, 0, 0};
    CHECK_REL(st_density_at(&d, centre), 2.0, 1e-12, 0);
    CHECK_REL(st_density_at(&d, ramp), 1.0, 1e-12, 0); // half way down the ramp [0.9, 1.1]

    // The reference through the box: an emitter behind it, the camera on the z
    // axis, an odd image so the centre pixel's ray is the axis.
    const double cam[3] = {0, 0, 6}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0}, sig_a = 0.3;
    st_scene s;
    scene_init(&s, 33, 33, cam, tgt, up, 40, 50);
    add_quad(&s, (double[]){-5, -5, -3}, (double[]){10, 0, 0}, (double[]){0, 10, 0}, 0.0, 1.0);
    set_medium(&s, 0.0, sig_a, ST_PHASE_ISOTROPIC, 0);
    s.density = d; // the scene owns the grid from here on
    double *want = calloc(33 * 33, sizeof *want);
    for (int j = 0; j < 33; j++)
        for (int i = 0; i < 33; i++) {
            double r[3];
            contract_ray(&s, i, j, r);
            want[j * 33 + i] = exp(-sig_a * st_density_integral(&d, cam, r, 0.0, 9.0 / -r[2]));
        }
    st_ref_options opt = {.spp = 1024, .aov = ST_REF_COMBINED, .seed = 3};
    st_image img;
    if (render(&s, &opt, &img)) {
        check_z("vdb box", &img, want);
        const float *c = st_image_px(&img, 16, 16), *corner = st_image_px(&img, 0, 0);
        fprintf(stderr, "  vdb box centre %.5f +- %.5f, e^(-sigma_t 4) = %.5f\n", c[0], c[3],
                exp(-4 * sig_a));
        CHECK(fabs(c[0] - exp(-4 * sig_a)) <= 5 * c[3] + 1e-6, "centre %.6g vs %.6g", c[0],
              exp(-4 * sig_a));
        CHECK(corner[0] == 1.0f && corner[3] == 0.0f, "a ray beside the box sees T = 1: %g +- %g",
              corner[0], corner[3]);
        st_image_free(&img);
    }
    free(want);
    st_scene_free(&s);
}

// ---- the scene format and the command line -----------------------------------

static void write_text(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    if (f) fputs(text, f), fclose(f);
}

static void write_scene(const char *path, const char *density) {
    char text[2048];
    snprintf(text, sizeof text,
             "{\"image\": {\"width\": 16, \"height\": 16},\n"
             " \"camera\": {\"position\": [0, 0, 6], \"target\": [0, 0, 0], \"fov_y\": 30},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 2, 2], \"intensity\": [3, 3, "
             "3]}],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-5, -5, -3], \"u\": [10, 0, 0], \"v\": "
             "[0, 10, 0]}, \"albedo\": [0.5, 0.5, 0.5]}],\n"
             " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.05, 0.05, 0.05], "
             "\"density\": %s}}\n",
             density);
    write_text(path, text);
}

// Loads a scene with this density; expects failure with `msg` in the message.
static void bad_density(const char *dir, const char *density, const char *msg) {
    char path[1024];
    snprintf(path, sizeof path, "%s/bad.json", dir);
    write_scene(path, density);
    st_scene s;
    st_err err = {0};
    bool ok = st_scene_load(path, &s, &err);
    CHECK(!ok && err.kind == ST_ERR_INPUT && strstr(err.msg, msg),
          "density %s: expected an input error with '%s', got %s '%s'", density, msg,
          ok ? "success" : "", err.msg);
    if (ok) st_scene_free(&s);
}

static void scene_format(const char *dir) {
    char path[1024];
    // Files: a good grid, one of vectors, one with a negative and one with a
    // NaN voxel, one with a non-zero background, and a directory.
    const struct {
        const char *file;
        st_test_vdb spec;
    } files[] = {
        {"vec.vdb", {.name = "density", .value = 1.0f, .voxel = 0.1, .vector_grid = true}},
        {"neg.vdb",
         {.name = "density",
          .n = {2, 2, 2},
          .value = 1.0f,
          .voxel = 0.1,
          .has_bad = true,
          .bad = {1, 0, 1},
          .bad_value = -0.5f}},
        {"nan.vdb",
         {.name = "density",
          .n = {2, 2, 2},
          .value = 1.0f,
          .voxel = 0.1,
          .has_bad = true,
          .bad = {0, 1, 0},
          .bad_value = NAN}},
        {"bg.vdb",
         {.name = "density", .n = {2, 2, 2}, .value = 1.0f, .background = 0.5f, .voxel = 0.1}},
        {"good.vdb",
         {.name = "density", .n = {4, 4, 4}, .origin = {-2, -2, -2}, .value = 1.0f, .voxel = 0.5}},
    };
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[k].file);
        CHECK(st_test_write_vdb(path, &files[k].spec), "writing %s", path);
    }
    snprintf(path, sizeof path, "%s/folder.vdb", dir);
    mkdir(path, 0755);

    bad_density(dir, "{\"height\": {\"base\": 0, \"falloff\": -0.5}}",
                "medium.density.height.falloff: -0.5 is out of range");
    bad_density(dir, "{\"height\": {\"base\": 0}}", "medium.density.height.falloff: required");
    bad_density(dir, "{\"height\": {\"base\": 0, \"falloff\": 1, \"top\": 3}}", "unknown key");
    bad_density(dir, "{\"height\": {\"base\": 0, \"falloff\": 1}, \"vdb\": \"good.vdb\"}",
                "not both");
    bad_density(dir, "{}", "expected a \"height\" or a \"vdb\" key");
    bad_density(dir, "{\"vdb\": \"good.vdb\", \"grid\": \"smoke\"}",
                "no grid named 'smoke' (the file has: density, temperature)");
    bad_density(dir, "{\"vdb\": \"vec.vdb\"}", "grid 'density' holds vec3s values, expected float");
    bad_density(dir, "{\"vdb\": \"neg.vdb\"}", "voxel (1, 0, 1) has density -0.5");
    bad_density(dir, "{\"vdb\": \"nan.vdb\"}", "voxel (0, 1, 0) has density nan");
    bad_density(dir, "{\"vdb\": \"bg.vdb\"}", "background value 0.5");
    bad_density(dir, "{\"vdb\": \"missing.vdb\"}", "missing.vdb: cannot open");
    bad_density(dir, "{\"vdb\": \"folder.vdb\"}", "folder.vdb: not a regular file");
    bad_density(dir, "{\"vdb\": \"good.vdb\", \"transform\": {\"scale\": [1, 0, 1]}}",
                "medium.density.transform.scale: element 1 is 0");
    bad_density(dir, "{\"vdb\": \"good.vdb\", \"transform\": {\"rotate\": [1, 0, 1]}}",
                "unknown key");
    snprintf(path, sizeof path, "%s/junk.vdb", dir);
    write_text(path, "not a vdb file at all");
    bad_density(dir, "{\"vdb\": \"junk.vdb\"}", "junk.vdb: not a readable OpenVDB file");

    // A good grid, relative to the scene's folder, with the transform applied.
    snprintf(path, sizeof path, "%s/good.json", dir);
    write_scene(path, "{\"vdb\": \"good.vdb\", \"transform\": {\"translate\": [1, 2, 3], "
                      "\"scale\": [2, 2, 2]}}");
    st_scene s;
    st_err err = {0};
    if (st_scene_load(path, &s, &err)) {
        // Voxels -2..1 and the ring: index -3..2 per axis; world = (1, 2, 3) + 2 * 0.5 i.
        CHECK(s.density.kind == ST_DENSITY_GRID, "kind %d", s.density.kind);
        CHECK_REL(s.density.grid->bmin[0], 1 - 3.0, 1e-12, 0);
        CHECK_REL(s.density.grid->bmax[1], 2 + 2.0, 1e-12, 0);
        const double at[3] = {1, 2, 3};
        CHECK_REL(st_density_at(&s.density, at), 1.0, 1e-12, 0);
        st_scene_free(&s);
    } else {
        CHECK(0, "good.json: %s", err.msg);
    }

    // The command line: render draws both (the GPU density, common/medium.glsl;
    // its accuracy is tests/toth's), reference renders.
    char out[1024], cmd[4096], buf[8192];
    snprintf(out, sizeof out, "%s/fog.exr", dir);
    snprintf(path, sizeof path, "%s/height.json", dir);
    write_scene(path, "{\"height\": {\"base\": 0, \"falloff\": 0.5}}");
    unlink(out);
    snprintf(cmd, sizeof cmd, "%s render %s -o %s", ST_TEST_STRAHL, path, out);
    int rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 0 && st_test_exists(out), "render of height fog: rc %d, '%s'", rc, buf);
    unlink(out);
    snprintf(cmd, sizeof cmd, "%s render %s/good.json -o %s", ST_TEST_STRAHL, dir, out);
    rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 0 && st_test_exists(out), "render of a vdb grid: rc %d, '%s'", rc, buf);
    snprintf(cmd, sizeof cmd, "cd / && %s reference %s/good.json -o %s --spp 4", ST_TEST_STRAHL,
             dir, out);
    rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 0 && st_test_exists(out), "reference of a vdb scene from another folder: rc %d",
          rc);
    write_scene(path, "{\"vdb\": \"good.vdb\", \"grid\": \"smoke\"}");
    unlink(out);
    snprintf(cmd, sizeof cmd, "%s reference %s -o %s --spp 1", ST_TEST_STRAHL, path, out);
    rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 2 && strstr(buf, "no grid named 'smoke'") && !st_test_exists(out),
          "reference with a bad grid name: rc %d", rc);
}

int main(void) {
    const char *dir = ST_TEST_SCRATCH;
    height_closed_form();
    grid_integral();
    emitter_through_height_fog();
    inscatter_height_fog(ST_PHASE_ISOTROPIC, 0, "in-scattering in height fog, isotropic");
    inscatter_height_fog(ST_PHASE_HG, 0.6, "in-scattering in height fog, HG 0.6");
    inscatter_height_fog_sun();
    vdb_box(dir);
    scene_format(dir);
    return st_test_summary("reference_fog");
}
