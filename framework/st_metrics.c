// Error metrics between a rendered image a and a reference b, and a heat map
// of their difference. Sums are in double: images reach millions of pixels.
#include "st_image.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

// Channel c (0..2) of pixel i; 1- and 2-channel images are grey.
static inline double chan(const st_image *img, size_t i, int c) {
    const float *p = img->data + i * img->channels;
    return img->channels >= 3 ? p[c] : p[0];
}

static bool check_pair(const st_image *a, const st_image *b, st_err *err) {
    if (!a || !b || !a->data || !b->data)
        return st_fail(err, ST_ERR_INPUT, "compare: missing image");
    if (a->width != b->width || a->height != b->height)
        return st_fail(err, ST_ERR_INPUT, "image size %dx%d does not match reference size %dx%d",
                       a->width, a->height, b->width, b->height);
    size_t na = st_image_count_nonfinite(a), nb = st_image_count_nonfinite(b);
    if (na) return st_fail(err, ST_ERR_INPUT, "image contains %zu non-finite (NaN/Inf) values", na);
    if (nb)
        return st_fail(err, ST_ERR_INPUT, "reference contains %zu non-finite (NaN/Inf) values", nb);
    return true;
}

bool st_image_compare(const st_image *a, const st_image *b, st_metrics *m, st_err *err) {
    *m = (st_metrics){0};
    if (!check_pair(a, b, err)) return false;
    const size_t n = (size_t)a->width * a->height;
    double se[4] = {0}, rel[4] = {0}, sa[4] = {0}, sb[4] = {0}, ab = 0, aa = 0, peak = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) {
            double x = chan(a, i, c), y = chan(b, i, c), d = x - y;
            se[c] += d * d;
            rel[c] += d * d / (y * y + 1e-2);
            sa[c] += x;
            sb[c] += y;
            ab += x * y;
            aa += x * x;
            if (fabs(d) > m->max_abs[c]) m->max_abs[c] = fabs(d);
            if (y > peak) peak = y;
        }
    }
    // A black (or negative) reference has no meaningful peak; use 1.
    if (!(peak > 0)) peak = 1;
    m->scale = aa > 0 ? ab / aa : 0;
    double sse[4] = {0};
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) {
            double d = m->scale * chan(a, i, c) - chan(b, i, c);
            sse[c] += d * d;
        }
    }
    for (int c = 0; c < 3; c++) {
        se[3] += se[c];
        rel[3] += rel[c];
        sa[3] += sa[c];
        sb[3] += sb[c];
        sse[3] += sse[c];
        if (m->max_abs[c] > m->max_abs[3]) m->max_abs[3] = m->max_abs[c];
    }
    for (int c = 0; c < 4; c++) {
        double cnt = c < 3 ? (double)n : 3.0 * n;
        m->rmse[c] = sqrt(se[c] / cnt);
        m->relmse[c] = rel[c] / cnt;
        m->psnr[c] = m->rmse[c] > 0 ? 20.0 * log10(peak / m->rmse[c]) : INFINITY;
        m->scaled_rmse[c] = sqrt(sse[c] / cnt);
        m->mean_a[c] = sa[c] / cnt;
        m->mean_b[c] = sb[c] / cnt;
    }
    return true;
}

bool st_image_compare_noisy(const st_image *a, const st_image *b, const st_image *b_stderr,
                            st_metrics *m, st_err *err) {
    if (!st_image_compare(a, b, m, err)) return false;
    for (int c = 0; c < 4; c++) {
        m->rmse_debiased[c] = m->rmse[c];
        m->relmse_debiased[c] = m->relmse[c];
        m->scaled_rmse_debiased[c] = m->scaled_rmse[c];
    }
    if (!b_stderr || !b_stderr->data) return true;
    if (b_stderr->width != b->width || b_stderr->height != b->height || b_stderr->channels < 3)
        return st_fail(err, ST_ERR_INPUT, "reference standard error is %dx%dx%d, expected %dx%dx3",
                       b_stderr->width, b_stderr->height, b_stderr->channels, b->width, b->height);
    size_t bad = st_image_count_nonfinite(b_stderr);
    if (bad)
        return st_fail(err, ST_ERR_INPUT, "reference standard error has %zu non-finite values",
                       bad);
    const size_t n = (size_t)a->width * a->height;
    double vv[4] = {0}, se[4] = {0}, rel[4] = {0}, sse[4] = {0};
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) {
            double x = chan(a, i, c), y = chan(b, i, c),
                   s = b_stderr->data[i * b_stderr->channels + c];
            double d = x - y, ds = m->scale * x - y, v = s * s;
            vv[c] += v;
            se[c] += d * d - v;
            // The weight w(b) = 1/(b^2 + 0.01) is noisy too and correlates
            // with d: to first order E[(d^2 - s^2) w(b)] = delta^2 w(mu)
            // - 2 delta s^2 w'(mu), w' = -2 mu w^2; the last term is
            // estimated from d, b, s and removed.
            double wgt = 1.0 / (y * y + 1e-2);
            rel[c] += (d * d - v) * wgt - 4.0 * d * y * v * wgt * wgt;
            sse[c] += ds * ds - v;
        }
    }
    m->has_ref_noise = true;
    for (int c = 0; c < 3; c++) {
        vv[3] += vv[c];
        se[3] += se[c];
        rel[3] += rel[c];
        sse[3] += sse[c];
    }
    for (int c = 0; c < 4; c++) {
        double cnt = c < 3 ? (double)n : 3.0 * n;
        m->ref_noise_rms[c] = sqrt(vv[c] / cnt);
        m->rmse_debiased[c] = sqrt(fmax(se[c] / cnt, 0.0));
        m->relmse_debiased[c] = fmax(rel[c] / cnt, 0.0);
        m->scaled_rmse_debiased[c] = sqrt(fmax(sse[c] / cnt, 0.0));
    }
    return true;
}

bool st_metrics_noise_dominates(const st_metrics *m) {
    return m->has_ref_noise && m->ref_noise_rms[3] > m->rmse_debiased[3] / 3.0;
}

// Ramp stops black - blue - red - yellow - white at t = 0, 1/4, 1/2, 3/4, 1.
void st_heat_colour(double t, uint8_t rgb[3]) {
    static const double stop[5][3] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}};
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double x = t * 4;
    int k = x >= 4 ? 3 : (int)x;
    double f = x - k;
    for (int c = 0; c < 3; c++) {
        double v = stop[k][c] + f * (stop[k + 1][c] - stop[k][c]);
        rgb[c] = (uint8_t)floor(v * 255.0 + 0.5);
    }
}

bool st_image_write_heatmap(const char *path, const st_image *a, const st_image *b, st_err *err) {
    if (!check_pair(a, b, err)) {
        st_err_prefix(err, "%s: ", path ? path : "");
        return false;
    }
    const size_t n = (size_t)a->width * a->height;
    double *d = malloc(n * sizeof *d);
    uint8_t *px = malloc(n * 3);
    if (!d || !px) {
        free(d);
        free(px);
        return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    }
    double dmax = 0;
    for (size_t i = 0; i < n; i++) {
        double s = 0;
        for (int c = 0; c < 3; c++)
            s += fabs(chan(a, i, c) - chan(b, i, c));
        d[i] = s / 3;
        if (d[i] > dmax) dmax = d[i];
    }
    if (dmax < 1e-12) dmax = 1e-12; // identical images give a black map
    for (size_t i = 0; i < n; i++)
        st_heat_colour(d[i] / dmax, px + 3 * i);
    bool ok = st_png_write8(path, px, a->width, a->height, 3, err);
    free(d);
    free(px);
    return ok;
}
