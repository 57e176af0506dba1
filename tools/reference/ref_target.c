// `strahl reference --target-error E`: passes of the reference until the
// image's estimated relative error is at most E. The estimate is what
// `strahl compare` would report as the debiased NRMSE of this image against
// its own expectation: sqrt(mean over values of stderr^2) / mean |value|.
#include "ref.h"
#include <math.h>
#include <stdlib.h>

double st_ref_relative_error(const st_image *img) {
    double se2 = 0.0, sum = 0.0;
    const size_t n = (size_t)img->width * img->height;
    for (size_t p = 0; p < n; p++)
        for (int c = 0; c < 3; c++) {
            double v = img->data[6 * p + c], s = img->data[6 * p + 3 + c];
            se2 += s * s, sum += fabs(v);
        }
    return sum > 0.0 ? sqrt(se2 / (3.0 * n)) / (sum / (3.0 * n)) : 0.0;
}

// acc (n_acc samples) += img (n samples) as `strahl merge` does: means
// weighted by spp, standard errors sqrt(sum n_i^2 s_i^2) / N.
static void merge_into(st_image *acc, long n_acc, const st_image *img, long n) {
    const double N = (double)(n_acc + n);
    const size_t count = (size_t)acc->width * acc->height;
    for (size_t p = 0; p < count; p++)
        for (int c = 0; c < 3; c++) {
            float *a = acc->data + 6 * p, *b = img->data + 6 * p;
            a[c] = (float)((n_acc * (double)a[c] + n * (double)b[c]) / N);
            double v =
                (double)n_acc * n_acc * a[3 + c] * a[3 + c] + (double)n * n * b[3 + c] * b[3 + c];
            a[3 + c] = (float)(sqrt(v) / N);
        }
}

bool st_ref_render_target(const st_scene *scene, const st_ref_options *o, double target,
                          long max_spp, st_image *out, long *spp_out, double *reached,
                          st_err *err) {
    st_ref_options pass = *o;
    if (!st_ref_render(scene, &pass, out, err)) return false;
    long total = pass.spp > 0 ? pass.spp : 1;
    double rel = st_ref_relative_error(out);
    for (int k = 1; rel > target && total < max_spp; k++) {
        // The 1/N law's estimate of the samples still missing (low-discrepancy
        // sampling converges faster, so this rather overshoots), at most 4x
        // the samples so far, so one bad estimate cannot run away.
        double want = ceil(total * ((rel / target) * (rel / target) - 1.0));
        long n = (long)fmin(fmin(want, 4.0 * total), (double)(max_spp - total));
        if (n < 1) n = 1;
        pass.spp = (int)n;
        pass.seed = st_ref_rng_hash(o->seed, (uint64_t)k); // independent of every pass
        st_image img;
        if (!st_ref_render(scene, &pass, &img, err)) {
            st_image_free(out);
            return false;
        }
        merge_into(out, total, &img, n);
        st_image_free(&img);
        total += n;
        rel = st_ref_relative_error(out);
    }
    *spp_out = total;
    *reached = rel;
    return true;
}
