// toth: the airlight table (airlight.h).
#include "airlight.h"
#include <math.h>

// p(cos 2 z) e^(-u (tan z - tz)) over [a, b] by 4-node Gauss-Legendre.
static double interval(double a, double b, double u, double tz, st_phase_kind kind, double g) {
    static const double x[2] = {0.339981043584856, 0.861136311594053};
    static const double w[2] = {0.652145154862546, 0.347854845137454};
    double mid = 0.5 * (a + b), half = 0.5 * (b - a), sum = 0.0;
    for (int n = 0; n < 2; n++) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            double z = mid + sgn * half * x[n];
            double e = u > 0.0 ? exp(-u * (tan(z) - tz)) : 1.0;
            sum += w[n] * st_phase_eval(kind, cos(2.0 * z), g) * e;
        }
    }
    return half * sum;
}

// The grid: column y in [0, 1] at xi = pi/2 (1 - (1 - y)^2) (finer toward
// pi/2, where a ray runs away from a light behind the camera and G bends
// within a few hundredths), row x in [0, 1) at sqrt(u) = sqrt(U0) x / (1 - x)
// (finer toward u = 0, where G near pi/2 goes like u log u).
static double col_xi(int c) {
    double y = 1.0 - (double)c / (TOTH_AIRLIGHT_NXI - 1);
    return 0.5 * ST_PI * (1.0 - y * y);
}

static double row_u(int r) {
    double x = (double)r / (TOTH_AIRLIGHT_NU - 1), q = x / (1.0 - x);
    return TOTH_AIRLIGHT_U0 * q * q;
}

void toth_airlight_fill(float *G, st_phase_kind kind, double g) {
    for (int r = 0; r < TOTH_AIRLIGHT_NU; r++) {
        float *row = G + (size_t)r * TOTH_AIRLIGHT_NXI;
        row[TOTH_AIRLIGHT_NXI - 1] = 0.0f;
        if (r == TOTH_AIRLIGHT_NU - 1) { // u = infinity
            for (int c = 0; c < TOTH_AIRLIGHT_NXI; c++)
                row[c] = 0.0f;
            continue;
        }
        double u = row_u(r), next = 0.0;
        for (int c = TOTH_AIRLIGHT_NXI - 2; c >= 0; c--) {
            double a = col_xi(c), b = col_xi(c + 1);
            double ta = tan(a);
            // The tail beyond b, shifted from tan(b) to tan(a); the last
            // interval has no tail (tan(pi/2) would be inf, and 0 * inf NaN).
            double carry = c + 1 < TOTH_AIRLIGHT_NXI - 1 ? exp(-u * (tan(b) - ta)) * next : 0.0;
            next = interval(a, b, u, ta, kind, g) + carry;
            row[c] = (float)next;
        }
    }
}

double toth_airlight_lookup(const float *G, double u, double xi) {
    double y = 1.0 - sqrt(fmax(1.0 - xi / (0.5 * ST_PI), 0.0)),
           q = sqrt(fmax(u, 0.0) / TOTH_AIRLIGHT_U0);
    double fx = fmin(y, 1.0) * (TOTH_AIRLIGHT_NXI - 1), fy = q / (1.0 + q) * (TOTH_AIRLIGHT_NU - 1);
    int cx = (int)fmin(floor(fx), TOTH_AIRLIGHT_NXI - 2),
        cy = (int)fmin(floor(fy), TOTH_AIRLIGHT_NU - 2);
    double ax = fx - cx, ay = fy - cy;
    const float *r0 = G + (size_t)cy * TOTH_AIRLIGHT_NXI, *r1 = r0 + TOTH_AIRLIGHT_NXI;
    double a = r0[cx] + ax * (r0[cx + 1] - r0[cx]), b = r1[cx] + ax * (r1[cx + 1] - r1[cx]);
    return a + ay * (b - a);
}

double toth_airlight_inscatter(const float *G, const st_inscatter_problem *p, double h_min) {
    st_equiangular e = st_equiangular_frame(p, h_min);
    if (!(e.length > 0.0)) return 0.0;
    double s = p->length; // as st_equiangular_frame: metres along the unit direction
    double xa = 0.25 * ST_PI + 0.5 * atan2(e.a, e.h), xb = fmin(xa + 0.5 * e.length, 0.5 * ST_PI);
    double b = s + e.a, Db = sqrt(e.h * e.h + b * b), u = p->sigma_t * e.h;
    double r = exp(-p->sigma_t * e.D) * toth_airlight_lookup(G, u, xa) -
               exp(-p->sigma_t * (s + Db)) * toth_airlight_lookup(G, u, xb);
    return p->sigma_s * p->intensity / e.h * 2.0 * r;
}
