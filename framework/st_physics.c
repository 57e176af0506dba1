// strahl: the radiometric model in plain C (see st_physics.h).
#include "st_physics.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "st_vec3.h"

// ---- Phase functions -------------------------------------------------------

static double clampd(double x, double lo, double hi) {
    return x < lo ? lo : x > hi ? hi : x;
}

double st_phase_isotropic(void) {
    return 1.0 / (4.0 * ST_PI);
}

double st_phase_rayleigh(double c) {
    c = clampd(c, -1.0, 1.0);
    return 3.0 / (16.0 * ST_PI) * (1.0 + c * c);
}

double st_phase_hg(double c, double g) {
    c = clampd(c, -1.0, 1.0);
    g = clampd(g, -0.999, 0.999); // |g| -> 1 is a delta; keep the peak finite
    // Rounding can push the base below 0 near c = 1, g = 1; never pow a negative.
    double base = fmax(1.0 + g * g - 2.0 * g * c, 0.0);
    return (1.0 - g * g) / (4.0 * ST_PI * base * sqrt(base));
}

double st_phase_eval(st_phase_kind kind, double c, double g) {
    switch (kind) {
    case ST_PHASE_RAYLEIGH:
        return st_phase_rayleigh(c);
    case ST_PHASE_HG:
        return st_phase_hg(c, g);
    case ST_PHASE_ISOTROPIC:
    default:
        return st_phase_isotropic();
    }
}

double st_phase_hg_thesis(double c, double g) {
    c = clampd(c, -1.0, 1.0);
    g = clampd(g, -0.999, 0.999);
    double base = fmax(1.0 + g * g - 2.0 * g * c, 1e-12);
    return (1.0 - g) * (1.0 - g) / base;
}

double st_phase_rayleigh_thesis(double c) {
    c = clampd(c, -1.0, 1.0);
    return c * c;
}

// ---- March steps -----------------------------------------------------------

bool st_integrator_parse(const char *name, st_integrator *out) {
    static const char *names[] = {"energy", "thesis", "thesis_far"};
    for (int i = 0; i < 3; i++)
        if (!strcmp(name, names[i])) {
            *out = (st_integrator)i;
            return true;
        }
    return false;
}

const char *st_integrator_name(st_integrator it) {
    switch (it) {
    case ST_INTEGRATOR_THESIS:
        return "thesis";
    case ST_INTEGRATOR_THESIS_FAR:
        return "thesis_far";
    case ST_INTEGRATOR_ENERGY:
    default:
        return "energy";
    }
}

double st_step_transfer(double sigma_t, double dt) {
    double x = sigma_t * dt;
    // expm1 keeps (1 - e^-x)/sigma_t accurate for small x; below 1e-9 the
    // series dt (1 - x/2) is exact to double precision and avoids 0/0.
    if (fabs(x) < 1e-9) return dt * (1.0 - 0.5 * x);
    return -expm1(-x) / sigma_t;
}

void st_march_step(st_march *m, st_integrator it, double S, double sigma_t, double dt) {
    double step_T = exp(-sigma_t * dt);
    switch (it) {
    case ST_INTEGRATOR_THESIS: // near end: transmittance before the step
        m->L += m->T * S * dt;
        m->T *= step_T;
        break;
    case ST_INTEGRATOR_THESIS_FAR: // far end: transmittance after the step
        m->T *= step_T;
        m->L += m->T * S * dt;
        break;
    case ST_INTEGRATOR_ENERGY:
    default: // integral_0^dt T e^(-sigma_t t) S dt, exact for constant S
        m->L += m->T * S * st_step_transfer(sigma_t, dt);
        m->T *= step_T;
        break;
    }
}

double st_march_constant(st_integrator it, double S, double sigma_t, double length, int steps) {
    if (steps < 1) steps = 1;
    st_march m = st_march_begin();
    double dt = length / steps;
    for (int i = 0; i < steps; i++)
        st_march_step(&m, it, S, sigma_t, dt);
    return m.L;
}

// ---- Adaptive Gauss-Kronrod 7/15 (QUADPACK qk15 nodes) ---------------------

static const double gk_x[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
static const double gk_wk[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
// Gauss weights of the odd Kronrod nodes gk_x[1], [3], [5], [7].
static const double gk_wg[4] = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

static double gk15(st_integrand f, void *ctx, double a, double b, double *err) {
    double c = 0.5 * (a + b), h = 0.5 * (b - a);
    double fc = f(c, ctx);
    double k = fc * gk_wk[7], g = fc * gk_wg[3];
    for (int i = 0; i < 7; i++) {
        double dx = h * gk_x[i];
        double s = f(c - dx, ctx) + f(c + dx, ctx);
        k += gk_wk[i] * s;
        if (i & 1) g += gk_wg[i / 2] * s;
    }
    *err = fabs((k - g) * h);
    return k * h;
}

// Global adaptivity: keep bisecting the panel with the largest error
// estimate until the summed estimate meets the tolerance. Unlike recursive
// bisection with a halved tolerance per level, this cannot chase rounding
// noise down to 2^depth panels; the panel cap bounds the work.
enum { GK_MAX_PANELS = 2000 };

typedef struct {
    double a, b, value, err;
} gk_panel;

double st_integrate(st_integrand f, void *ctx, double a, double b, double abs_tol, double rel_tol) {
    if (a == b) return 0.0;
    gk_panel panels[GK_MAX_PANELS]; // on the stack: integrands may integrate (nesting)
    int n = 0;
    // Start from 4 panels so a narrow feature is less likely to be missed.
    for (int i = 0; i < 4; i++) {
        gk_panel *p = &panels[n++];
        p->a = a + (b - a) * i / 4.0;
        p->b = i == 3 ? b : a + (b - a) * (i + 1) / 4.0;
        p->value = gk15(f, ctx, p->a, p->b, &p->err);
    }
    for (;;) {
        double value = 0.0, err = 0.0;
        int worst = 0;
        for (int i = 0; i < n; i++) {
            value += panels[i].value;
            err += panels[i].err;
            if (panels[i].err > panels[worst].err) worst = i;
        }
        double tol = fmax(abs_tol, rel_tol * fabs(value));
        gk_panel *w = &panels[worst];
        double m = 0.5 * (w->a + w->b);
        if (err <= tol || n >= GK_MAX_PANELS || m <= w->a || m >= w->b) return value;
        gk_panel right = {m, w->b, 0.0, 0.0};
        right.value = gk15(f, ctx, m, w->b, &right.err);
        w->b = m;
        w->value = gk15(f, ctx, w->a, m, &w->err);
        panels[n++] = right;
    }
}

// ---- Single scattering -----------------------------------------------------

double st_inscatter_integrand(const st_inscatter_problem *p, double t) {
    double dl = st_len3(p->dir);
    double x[3], to_light[3];
    for (int k = 0; k < 3; k++)
        x[k] = p->origin[k] + p->dir[k] / dl * t;
    st_sub3(to_light, p->light, x);
    double d2 = st_dot3(to_light, to_light), d = sqrt(d2);
    if (d2 == 0.0) return INFINITY;
    double c = st_dot3(to_light, p->dir) / (d * dl);
    return exp(-p->sigma_t * t) * p->sigma_s * st_phase_eval(p->phase, c, p->g) * p->intensity /
           d2 * exp(-p->sigma_t * d);
}

double st_inscatter_quadrature(const st_inscatter_problem *p, int steps) {
    int n = steps < 2 ? 2 : steps + (steps & 1);
    double h = p->length / n,
           sum = st_inscatter_integrand(p, 0.0) + st_inscatter_integrand(p, p->length);
    for (int i = 1; i < n; i++)
        sum += (i & 1 ? 4.0 : 2.0) * st_inscatter_integrand(p, i * h);
    return sum * h / 3.0;
}

double st_inscatter_atan(double sigma_s, double intensity, double h, double a, double b) {
    return sigma_s * intensity / (4.0 * ST_PI) * (atan(b / h) - atan(a / h)) / h;
}

typedef struct {
    double u;
} sun_ctx;

static double sun_f(double x, void *ctx) {
    double u = ((sun_ctx *)ctx)->u;
    double t = tan(x);
    return isfinite(t) ? exp(-u * t) : 0.0;
}

// integral_v0^v1 e^(-u tan x) dx; taking the difference as one integral
// avoids cancelling two nearly equal F values when the interval is short.
static double sun_F_range(double u, double v0, double v1) {
    if (u == 0.0) return v1 - v0;
    sun_ctx c = {u};
    return st_integrate(sun_f, &c, v0, v1, 1e-300, 1e-12);
}

double st_sun_F(double u, double v) {
    return sun_F_range(u, 0.0, v);
}

typedef struct {
    double sigma_t, D, cg, sg; // the light at (D cos gamma, D sin gamma) in the ray's frame
} sun_direct_ctx;

static double sun_direct_f(double t, void *ctx) {
    const sun_direct_ctx *c = ctx;
    double dx = c->D * c->cg - t, dy = c->D * c->sg, d2 = dx * dx + dy * dy, d = sqrt(d2);
    return exp(-c->sigma_t * (t + d)) / d2;
}

double st_inscatter_sun(double sigma_s, double sigma_t, double I, double D, double gamma,
                        double s) {
    double sg = sin(gamma), cg = cos(gamma), h = D * sg;
    if (sg < 1e-3) {
        // The ray passes within D/1000 of the light's line: the closed form
        // loses digits to its 1/sin(gamma), so integrate directly, splitting
        // at the foot point where the integrand peaks.
        double foot = D * cg;
        if (h == 0.0 && foot >= 0.0 && foot <= s) return INFINITY; // light on the segment
        sun_direct_ctx c = {sigma_t, D, cg, sg};
        double sum = 0.0;
        if (foot > 0.0 && foot < s)
            sum = st_integrate(sun_direct_f, &c, 0.0, foot, 0.0, 1e-12) +
                  st_integrate(sun_direct_f, &c, foot, s, 0.0, 1e-12);
        else
            sum = st_integrate(sun_direct_f, &c, 0.0, s, 0.0, 1e-12);
        return sigma_s * I / (4.0 * ST_PI) * sum;
    }
    double beta = sigma_t;
    double A1 = beta * h;
    // v1 = pi/4 + atan((s - D cos g) / (D sin g)) / 2, written as half the
    // angle atan2(h, D cos g - s) so it stays exact when that ratio is large.
    double v1 = 0.5 * atan2(h, D * cg - s);
    double integral = sun_F_range(A1, 0.5 * gamma, v1);
    if (beta == 0.0) // A0 (F - F) / sigma_t in the limit sigma_t -> 0
        return sigma_s * I * exp(-beta * D * cg) / (2.0 * ST_PI * h) * integral;
    double A0 = beta * I * exp(-beta * D * cg) / (2.0 * ST_PI * h);
    return A0 * integral * (sigma_s / sigma_t);
}

double st_inscatter_sun_problem(const st_inscatter_problem *p) {
    double to_light[3];
    st_sub3(to_light, p->light, p->origin);
    double D = st_len3(to_light), dl = st_len3(p->dir);
    double c = clampd(st_dot3(to_light, p->dir) / (D * dl), -1.0, 1.0);
    // acos loses precision near +-1; atan2 of |cross| and dot does not.
    double cr[3];
    st_cross3(cr, to_light, p->dir);
    double gamma = atan2(st_len3(cr) / (D * dl), c);
    return st_inscatter_sun(p->sigma_s, p->sigma_t, p->intensity, D, gamma, p->length);
}

// ---- Form factors ----------------------------------------------------------

double st_ff_point_polygon(const double p[3], const double n[3], const double (*v)[3], int count) {
    if (count < 3) return 0.0;
    // Clip to the half-space in front of p (Sutherland-Hodgman) so Lambert's
    // formula only sees the visible part; at most one vertex per edge is added.
    double(*poly)[3] = malloc(sizeof *poly * (size_t)(2 * count));
    if (!poly) return NAN;
    int m = 0;
    for (int i = 0; i < count; i++) {
        const double *a = v[i], *b = v[(i + 1) % count];
        double ra[3], rb[3];
        st_sub3(ra, a, p);
        st_sub3(rb, b, p);
        double da = st_dot3(ra, n), db = st_dot3(rb, n);
        if (da >= 0.0) memcpy(poly[m++], a, sizeof poly[0]);
        if ((da >= 0.0) != (db >= 0.0)) {
            double t = da / (da - db);
            for (int k = 0; k < 3; k++)
                poly[m][k] = a[k] + t * (b[k] - a[k]);
            m++;
        }
    }
    double sum = 0.0;
    for (int i = 0; i < m; i++) {
        double ra[3], rb[3], cr[3];
        st_sub3(ra, poly[i], p);
        st_sub3(rb, poly[(i + 1) % m], p);
        st_cross3(cr, ra, rb);
        double cl = st_len3(cr);
        if (cl <= 1e-300) continue; // p on the edge's line: the edge subtends no area
        double angle = atan2(cl, st_dot3(ra, rb));
        sum += angle * st_dot3(n, cr) / cl;
    }
    free(poly);
    return fabs(sum) / (2.0 * ST_PI);
}

double st_ff_point_disk(double R, double h) {
    return R * R / (R * R + h * h);
}

double st_ff_parallel_rects(double a, double b, double c) {
    double X = a / c, Y = b / c, X2 = X * X, Y2 = Y * Y;
    double sx = sqrt(1.0 + X2), sy = sqrt(1.0 + Y2);
    double f = 0.5 * log((1.0 + X2) * (1.0 + Y2) / (1.0 + X2 + Y2)) + X * sy * atan(X / sy) +
               Y * sx * atan(Y / sx) - X * atan(X) - Y * atan(Y);
    return 2.0 / (ST_PI * X * Y) * f;
}

double st_ff_perpendicular_rects(double l, double w, double h) {
    double W = w / l, H = h / l, W2 = W * W, H2 = H * H, S2 = W2 + H2, S = sqrt(S2);
    double lg = log((1.0 + W2) * (1.0 + H2) / (1.0 + S2)) +
                W2 * log(W2 * (1.0 + S2) / ((1.0 + W2) * S2)) +
                H2 * log(H2 * (1.0 + S2) / ((1.0 + H2) * S2));
    return (W * atan(1.0 / W) + H * atan(1.0 / H) - S * atan(1.0 / S) + 0.25 * lg) / (ST_PI * W);
}

typedef struct {
    const double *ca, *ua, *va, *n;
    double quad[4][3];
    double s; // the outer coordinate while the inner integral runs
} ff_ctx;

static double ff_inner(double t, void *vctx) {
    ff_ctx *c = vctx;
    double p[3];
    for (int k = 0; k < 3; k++)
        p[k] = c->ca[k] + c->s * c->ua[k] + t * c->va[k];
    return st_ff_point_polygon(p, c->n, (const double(*)[3])c->quad, 4);
}

static double ff_outer(double s, void *vctx) {
    ff_ctx *c = vctx;
    c->s = s;
    return st_integrate(ff_inner, c, 0.0, 1.0, 1e-13, 1e-11);
}

double st_ff_parallelograms(const double ca[3], const double ua[3], const double va[3],
                            const double cb[3], const double ub[3], const double vb[3]) {
    double n[3];
    st_cross3(n, ua, va);
    double nl = st_len3(n);
    for (int k = 0; k < 3; k++)
        n[k] /= nl;
    ff_ctx c = {ca, ua, va, n, {{0}}, 0.0};
    for (int k = 0; k < 3; k++) {
        c.quad[0][k] = cb[k];
        c.quad[1][k] = cb[k] + ub[k];
        c.quad[2][k] = cb[k] + ub[k] + vb[k];
        c.quad[3][k] = cb[k] + vb[k];
    }
    // The parametrisation has a constant Jacobian, so the unit-square
    // integral is already the area average.
    return st_integrate(ff_outer, &c, 0.0, 1.0, 1e-12, 1e-10);
}

double st_area_kernel(double a, double d2) {
    return ST_PI * a / (ST_PI * d2 + a);
}

// ---- Equi-angular quadrature ------------------------------------------------

st_equiangular st_equiangular_frame(const st_inscatter_problem *p, double h_min) {
    double dl = st_len3(p->dir), rel[3], cr[3];
    st_sub3(rel, p->light, p->origin);
    st_cross3(cr, rel, p->dir);
    double t_foot = st_dot3(rel, p->dir) / dl;
    st_equiangular e;
    e.h = fmax(st_len3(cr) / dl, h_min);
    e.a = -t_foot;
    e.D = sqrt(e.h * e.h + e.a * e.a);
    double b = p->length - t_foot;
    // atan(b/h) - atan(a/h) as one atan2: exact for short segments far away.
    e.length = p->length > 0.0 ? atan2(e.h * (b - e.a), e.h * e.h + e.a * b) : 0.0;
    return e;
}

void st_equiangular_point(const st_equiangular *e, double delta, double *t, double *d) {
    double s = sin(delta), c = cos(delta);
    double dcos = e->h * c - e->a * s; // D cos(theta) > 0
    *t = e->D * e->D * s / dcos;
    *d = e->h * e->D / dcos;
}

static const double gl4_x[2] = {0.339981043584856264802665759103, 0.861136311594052575223946488893};
static const double gl4_w[2] = {0.652145154862546142626936050778, 0.347854845137453857373063949222};

// Gauss-Legendre with 4 nodes on each of `panels` equal panels of [lo, hi].
static double eq_panels(const st_inscatter_problem *p, const st_equiangular *e, double lo,
                        double hi, int panels) {
    double w = (hi - lo) / panels, sum = 0.0;
    for (int k = 0; k < panels; k++) {
        double mid = lo + (k + 0.5) * w;
        for (int n = 0; n < 4; n++) {
            double delta = mid + (n & 1 ? -1 : 1) * 0.5 * w * gl4_x[n >> 1], t, d;
            st_equiangular_point(e, delta, &t, &d);
            double cos_theta = -(t + e->a) / d; // toward the light, against the view ray
            sum += 0.5 * w * gl4_w[n >> 1] * st_phase_eval(p->phase, cos_theta, p->g) *
                   exp(-p->sigma_t * (t + d));
        }
    }
    return sum;
}

int st_equiangular_split(const st_equiangular *e, int panels, double *foot) {
    // The foot point (theta = 0) separates the side toward the light, where
    // the phase function peaks for g > 0, from the side away from it, where
    // the path length t + d grows fastest: each gets its own panels.
    *foot = atan2(-e->a, e->h);
    if (panels < 2 || *foot <= 0.0 || *foot >= e->length) return 0;
    int before = (int)floor(panels * *foot / e->length + 0.5);
    return before < 1 ? 1 : before > panels - 1 ? panels - 1 : before;
}

double st_inscatter_equiangular(const st_inscatter_problem *p, int nodes, double h_min) {
    st_equiangular e = st_equiangular_frame(p, h_min);
    if (e.length <= 0.0 || e.h <= 0.0) return 0.0;
    int panels = nodes < 4 ? 1 : (nodes + 3) / 4;
    double foot;
    int before = st_equiangular_split(&e, panels, &foot);
    double sum = before ? eq_panels(p, &e, 0.0, foot, before) +
                              eq_panels(p, &e, foot, e.length, panels - before)
                        : eq_panels(p, &e, 0.0, e.length, panels);
    return sum * p->sigma_s * p->intensity / e.h;
}

void st_medium_sigma_t(const st_medium_desc *m, double out[3]) {
    for (int c = 0; c < 3; c++)
        out[c] = m->present ? (double)m->sigma_s[c] + (double)m->sigma_a[c] : 0.0;
}

void st_transmittance(const double sigma_t[3], double d, double out[3]) {
    for (int c = 0; c < 3; c++)
        out[c] = sigma_t[c] > 0.0 ? exp(-sigma_t[c] * d) : 1.0;
}

// ---- Heterogeneous media ---------------------------------------------------

// Index coordinates of world point x relative to the block's voxel 0.
static void grid_local(const st_density_grid *g, const double x[3], double u[3]) {
    for (int r = 0; r < 3; r++)
        u[r] = g->to_index[4 * r] * x[0] + g->to_index[4 * r + 1] * x[1] +
               g->to_index[4 * r + 2] * x[2] + g->to_index[4 * r + 3] - g->lo[r];
}

static double grid_voxel(const st_density_grid *g, long i, long j, long k) {
    if (i < 0 || j < 0 || k < 0 || i >= g->n[0] || j >= g->n[1] || k >= g->n[2]) return 0.0;
    return g->values[((size_t)k * (size_t)g->n[1] + (size_t)j) * (size_t)g->n[0] + (size_t)i];
}

// Trilinear between voxel centres at local coordinates u; 0 outside the block.
static double grid_sample(const st_density_grid *g, const double u[3]) {
    for (int r = 0; r < 3; r++)
        if (!(u[r] >= 0.0 && u[r] <= g->n[r] - 1)) return 0.0;
    long i = (long)floor(u[0]), j = (long)floor(u[1]), k = (long)floor(u[2]);
    double fx = u[0] - i, fy = u[1] - j, fz = u[2] - k, v = 0.0;
    for (int c = 0; c < 8; c++) {
        double w =
            ((c & 1) ? fx : 1.0 - fx) * ((c & 2) ? fy : 1.0 - fy) * ((c & 4) ? fz : 1.0 - fz);
        if (w != 0.0) v += w * grid_voxel(g, i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
    }
    return v;
}

double st_density_at(const st_density_desc *d, const double x[3]) {
    if (!d) return 1.0;
    switch (d->kind) {
    case ST_DENSITY_HEIGHT:
        return exp(-d->falloff * (x[1] - d->base));
    case ST_DENSITY_GRID: {
        double u[3];
        grid_local(d->grid, x, u);
        return grid_sample(d->grid, u);
    }
    case ST_DENSITY_UNIFORM:
    default:
        return 1.0;
    }
}

double st_height_fog_integral(double base, double falloff, double y, double dy, double length) {
    if (!(length > 0.0)) return 0.0;
    double y_low = dy < 0.0 ? y + dy * length : y;
    double x = falloff * fabs(dy) * length;
    double shape = x > 0.0 ? -expm1(-x) / x : 1.0;
    return length * exp(-falloff * (y_low - base)) * shape;
}

// The segment's parameter range inside the grid's block [0, n - 1]^3 (slabs
// in index space; the map is affine, so t is the world ray's parameter).
static bool grid_clip(const st_density_grid *g, const double o[3], const double w[3], double *t0,
                      double *t1) {
    double u0[3], du[3];
    grid_local(g, o, u0);
    for (int r = 0; r < 3; r++)
        du[r] = g->to_index[4 * r] * w[0] + g->to_index[4 * r + 1] * w[1] +
                g->to_index[4 * r + 2] * w[2];
    double a = *t0, b = *t1;
    for (int r = 0; r < 3; r++) {
        double hi = g->n[r] - 1;
        if (du[r] == 0.0) {
            if (!(u0[r] >= 0.0 && u0[r] <= hi)) return false;
            continue;
        }
        double ta = (0.0 - u0[r]) / du[r], tb = (hi - u0[r]) / du[r];
        if (ta > tb) {
            double x = ta;
            ta = tb, tb = x;
        }
        a = fmax(a, ta), b = fmin(b, tb);
    }
    if (!(b > a)) return false;
    *t0 = a, *t1 = b;
    return true;
}

// Exact integral of the trilinear density: DDA over the planes u_r = integer
// (cell faces), 2-point Gauss-Legendre per piece (the integrand is a cubic
// polynomial in t inside a cell).
static double grid_integral(const st_density_grid *g, const double o[3], const double w[3],
                            double t0, double t1) {
    if (!grid_clip(g, o, w, &t0, &t1)) return 0.0;
    double u0[3], du[3], next[3], step[3];
    grid_local(g, o, u0);
    for (int r = 0; r < 3; r++) {
        du[r] = g->to_index[4 * r] * w[0] + g->to_index[4 * r + 1] * w[1] +
                g->to_index[4 * r + 2] * w[2];
        double u = u0[r] + t0 * du[r];
        if (du[r] > 0.0) {
            next[r] = t0 + (floor(u) + 1.0 - u) / du[r];
            step[r] = 1.0 / du[r];
        } else if (du[r] < 0.0) {
            next[r] = t0 + (ceil(u) - 1.0 - u) / du[r];
            step[r] = -1.0 / du[r];
        } else {
            next[r] = step[r] = INFINITY;
        }
    }
    const double gl = 0.5 / sqrt(3.0);
    double sum = 0.0, t = t0;
    // Every piece but the last ends on a plane; there are at most n - 1 per axis.
    long budget = (long)g->n[0] + g->n[1] + g->n[2] + 8;
    while (t < t1 && budget-- > 0) {
        int r = next[0] <= next[1] && next[0] <= next[2] ? 0 : next[1] <= next[2] ? 1 : 2;
        double te = fmin(next[r], t1);
        if (te > t) {
            double mid = 0.5 * (t + te), half = te - t, p[3];
            for (int s = -1; s <= 1; s += 2) {
                double ts = mid + s * gl * half;
                for (int k = 0; k < 3; k++)
                    p[k] = u0[k] + ts * du[k];
                sum += 0.5 * half * grid_sample(g, p);
            }
            t = te;
        }
        next[r] += step[r];
    }
    return sum;
}

double st_density_integral(const st_density_desc *d, const double o[3], const double w[3],
                           double t0, double t1) {
    if (!(t1 > t0)) return 0.0;
    if (!d || d->kind == ST_DENSITY_UNIFORM) return t1 - t0;
    if (d->kind == ST_DENSITY_HEIGHT)
        return st_height_fog_integral(d->base, d->falloff, o[1] + t0 * w[1], w[1], t1 - t0);
    return grid_integral(d->grid, o, w, t0, t1);
}

bool st_density_clip(const st_density_desc *d, const double o[3], const double w[3], double *t0,
                     double *t1) {
    if (!(*t1 > *t0)) return false;
    if (d && d->kind == ST_DENSITY_GRID) return grid_clip(d->grid, o, w, t0, t1);
    return true;
}

double st_density_majorant(const st_density_desc *d, const double o[3], const double w[3],
                           double t0, double t1) {
    if (!d) return 1.0;
    switch (d->kind) {
    case ST_DENSITY_HEIGHT: {
        double y_low = fmin(o[1] + t0 * w[1], o[1] + t1 * w[1]);
        return exp(-d->falloff * (y_low - d->base));
    }
    case ST_DENSITY_GRID:
        return d->grid->max_value;
    case ST_DENSITY_UNIFORM:
    default:
        return 1.0;
    }
}

void st_segment_transmittance(const double sigma_t[3], const st_density_desc *d, const double o[3],
                              const double w[3], double t0, double t1, double out[3]) {
    st_transmittance(sigma_t, st_density_integral(d, o, w, t0, t1), out);
}

double st_direct_point(double rho, double intensity, double cos_theta, double d, double sigma_t) {
    if (!(d > 0.0)) return 0.0;
    return st_direct_lambert(rho, intensity / (d * d), cos_theta, d, sigma_t);
}

double st_spot_falloff(double cos_axis, double inner, double outer) {
    double co = cos(outer), scale = 1.0 / fmax(0.001, cos(inner) - co);
    double a = fmin(fmax((cos_axis - co) * scale, 0.0), 1.0);
    return a * a;
}

double st_directional_entry(const st_scene *scene, const float direction[3]) {
    double lo[3], hi[3];
    if (!st_scene_bounds(scene, lo, hi)) return -INFINITY;
    double e = -INFINITY;
    for (int k = 0; k < 8; k++) {
        double c[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        e = fmax(e, -(c[0] * direction[0] + c[1] * direction[1] + c[2] * direction[2]));
    }
    return e;
}

bool st_light_incident(const st_light_desc *l, double entry, const double x[3], st_incident *out) {
    memset(out, 0, sizeof *out);
    if (l->type == ST_LIGHT_DIRECTIONAL) {
        for (int k = 0; k < 3; k++)
            out->to_light[k] = -l->direction[k], out->E[k] = l->intensity[k];
        out->dist = INFINITY;
        double along = x[0] * out->to_light[0] + x[1] * out->to_light[1] + x[2] * out->to_light[2];
        out->path = fmax(0.0, entry - along);
        return true;
    }
    double v[3] = {l->position[0] - x[0], l->position[1] - x[1], l->position[2] - x[2]};
    double d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (!(d2 > 0.0)) return false;
    double d = sqrt(d2), f = 1.0;
    for (int k = 0; k < 3; k++)
        out->to_light[k] = v[k] / d;
    if (l->type == ST_LIGHT_SPOT) {
        double c = -(out->to_light[0] * l->direction[0] + out->to_light[1] * l->direction[1] +
                     out->to_light[2] * l->direction[2]);
        f = st_spot_falloff(c, l->inner_angle, l->outer_angle);
        if (!(f > 0.0)) return false;
    }
    out->dist = out->path = d;
    for (int k = 0; k < 3; k++)
        out->E[k] = l->intensity[k] * f / d2;
    return true;
}
