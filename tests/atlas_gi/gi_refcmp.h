// Error of an image against a noisy Monte Carlo reference that carries its
// per-pixel standard error (strahl reference writes stderr.R/G/B). Since
// E[(a - r)^2] = (a - b)^2 + s^2 for a reference r = b + noise of standard
// error s, subtracting s^2 gives an unbiased estimate of the error against
// the exact image b. The issue's metrics:
//   relMSE = mean((a - b)^2 / (b^2 + 0.01)),  NRMSE = rmse / mean(b)
// `noise_*` is the part of the raw metric the reference's noise explains;
// it must be small next to any bound a test asserts.
#ifndef GI_REFCMP_H
#define GI_REFCMP_H
#include "st_image.h"
#include <math.h>

typedef struct gi_refcmp {
    double relmse, nrmse;             // noise-corrected
    double relmse_raw, nrmse_raw;     // as measured against the noisy reference
    double noise_relmse, noise_nrmse; // the reference's own contribution
    double mean_a, mean_b;
} gi_refcmp;

// Both images must have the same size; `ref` holds R, G, B, stderr.R/G/B.
// block > 1 compares block means (block x block pixels), which divides the
// reference's noise variance by block^2.
static inline bool gi_refcmp_images(const st_image *a, const st_image *ref, int block,
                                    gi_refcmp *m) {
    if (a->width != ref->width || a->height != ref->height || ref->channels < 6 || a->channels < 3)
        return false;
    if (block < 1) block = 1;
    int bw = a->width / block, bh = a->height / block;
    double se = 0, se_rel = 0, nz = 0, nz_rel = 0, sa = 0, sb = 0;
    long n = 0;
    for (int by = 0; by < bh; by++)
        for (int bx = 0; bx < bw; bx++)
            for (int c = 0; c < 3; c++) {
                double va = 0, vb = 0, var = 0;
                for (int j = 0; j < block; j++)
                    for (int i = 0; i < block; i++) {
                        const float *pa = st_image_px(a, bx * block + i, by * block + j);
                        const float *pr = st_image_px(ref, bx * block + i, by * block + j);
                        va += pa[c], vb += pr[c], var += (double)pr[3 + c] * pr[3 + c];
                    }
                double k = (double)block * block;
                va /= k, vb /= k, var /= k * k;
                double d2 = (va - vb) * (va - vb), den = vb * vb + 0.01;
                se += d2, se_rel += d2 / den, nz += var, nz_rel += var / den;
                sa += va, sb += vb, n++;
            }
    if (!n) return false;
    m->mean_a = sa / n, m->mean_b = sb / n;
    m->relmse_raw = se_rel / n;
    m->noise_relmse = nz_rel / n;
    m->relmse = fmax(se_rel - nz_rel, 0) / n;
    double mb = m->mean_b > 0 ? m->mean_b : 1;
    m->nrmse_raw = sqrt(se / n) / mb;
    m->noise_nrmse = sqrt(nz / n) / mb;
    m->nrmse = sqrt(fmax(se - nz, 0) / n) / mb;
    return true;
}

static inline bool gi_refcmp_files(const char *img, const char *ref, int block, gi_refcmp *m,
                                   st_err *err) {
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    st_image a = {0}, r = {0};
    bool ok = st_image_read_exr(img, &a, err) && st_image_read_exr_channels(ref, names, 6, &r, err);
    if (ok && !gi_refcmp_images(&a, &r, block, m))
        ok = st_fail(err, ST_ERR_INPUT, "%s, %s: sizes differ", img, ref);
    st_image_free(&a);
    st_image_free(&r);
    return ok;
}
#endif
