// strahl: float images (linear radiance), EXR and PNG I/O, error metrics.
// Rows are stored top row first (j = 0 is the top of the picture).
#ifndef ST_IMAGE_H
#define ST_IMAGE_H
#include "st_base.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_image {
    int width, height, channels; // channels: 1, 3 or 4 (more for named EXR layers)
    float *data;                 // width * height * channels
} st_image;

// Zero-filled; channels may be 1..ST_IMAGE_MAX_CHANNELS.
#define ST_IMAGE_MAX_CHANNELS 64
bool st_image_alloc(st_image *img, int width, int height, int channels, st_err *err);
void st_image_free(st_image *img);
static inline float *st_image_px(const st_image *img, int i, int j) {
    return img->data + ((size_t)j * img->width + i) * img->channels;
}
// Counts NaN/Inf values.
size_t st_image_count_nonfinite(const st_image *img);

// Writes atomically: to a temporary file beside `path`, renamed on success, so
// a failure leaves no partial output. EXR: 32-bit float, channels R,G,B(,A).
// Extra single channels (e.g. per-pixel standard error) can be added with
// st_image_write_exr_named. Errors name the path: any NaN/Inf value ->
// ST_ERR_RUNTIME with the count (nothing is written); a file that cannot be
// created -> ST_ERR_RUNTIME; bad arguments -> ST_ERR_INPUT. ZIP compression;
// 1 channel is written as Y.
bool st_image_write_exr(const char *path, const st_image *img, st_err *err);
// `names[k]` names channel k of `img` (e.g. "R","G","B","stderr.R",...).
bool st_image_write_exr_named(const char *path, const st_image *img, const char *const *names,
                              st_err *err);
// Header attributes of a Monte Carlo image: `spp` (int) and `strahl.seeds`
// (the seeds of the runs it averages, comma-separated), so shards rendered
// with different seeds can be merged with the right weights, and
// `strahl.config` so shards of different renders are not. 0 / "": absent.
typedef struct st_exr_meta {
    int spp;
    char seeds[4096];
    char config[1024]; // `strahl.config`: what was rendered (scene, size, options)
    char filter[16];   // `strahl.filter`: the pixel filter, "box" or "point"; "" absent
    bool has_spp;      // read: the file has an spp attribute (spp keeps its value, even <= 0)
} st_exr_meta;
bool st_image_write_exr_meta(const char *path, const st_image *img, const char *const *names,
                             const st_exr_meta *meta, st_err *err);
bool st_image_read_exr_meta(const char *path, st_exr_meta *meta, st_err *err);
// The per-pixel standard error channels stderr.R/G/B as a 3-channel image;
// `out` stays empty (data NULL, still true) when the file has none.
bool st_image_read_exr_stderr(const char *path, st_image *out, st_err *err);
// Any scanline or tiled (level 0) EXR, HALF or FLOAT, first part: R,G,B(,A)
// as 3 (4) channels, else Y as 1 channel. `out` is allocated; free it.
bool st_image_read_exr(const char *path, st_image *out, st_err *err); // RGB(A) as float
// Reads exactly the named channels, in the given order (e.g. the stderr.*
// layers written by st_image_write_exr_named).
bool st_image_read_exr_channels(const char *path, const char *const *names, int count,
                                st_image *out, st_err *err);
// PNG: radiance * 2^exposure, clamped, sRGB-encoded, 8 bit.
bool st_image_write_png(const char *path, const st_image *img, float exposure, st_err *err);
// Writes by extension (.exr or .png); anything else is an ST_ERR_INPUT error.
bool st_image_write(const char *path, const st_image *img, float exposure, st_err *err);
// 8-bit pixels (comp 1..4, rows top first, tightly packed) as PNG, atomically.
bool st_png_write8(const char *path, const uint8_t *px, int width, int height, int comp,
                   st_err *err);
// As st_png_write8, with tEXt chunks (after IHDR): `text` holds key, value
// pairs, NULL-terminated. Keys are 1..79 printable Latin-1 characters, values
// have no control characters (so the metadata cannot forge lines).
bool st_png_write8_text(const char *path, const uint8_t *px, int width, int height, int comp,
                        const char *const *text, st_err *err);
// Exact piecewise sRGB OETF of a linear value in [0, 1].
double st_srgb_encode(double linear);

// Error metrics between two images of equal size (first 3 channels; a 1- or
// 2-channel image counts as grey). Non-finite values or a size mismatch are
// ST_ERR_INPUT errors.
typedef struct st_metrics {
    double rmse[4];   // per channel R,G,B and [3] = all
    double relmse[4]; // mean((a-b)^2 / (b^2 + 1e-2)), b the reference
    double psnr[4];   // 20 log10(peak / rmse), peak = max of the reference over R,G,B
                      // (1 if that is <= 0); +inf where rmse = 0
    double max_abs[4];
    double scale;          // s minimising |s a - b|^2 over R,G,B (0 if a is all zero),
                           // for methods that are not physically scaled
    double scaled_rmse[4]; // rmse of s a against b
    double mean_a[4], mean_b[4];
    // With the reference's per-pixel standard error s (st_image_compare_noisy):
    // E[(a-b)^2] = (a-mu)^2 + s^2 for a reference b of mean mu, so the error
    // against mu is estimated without bias by mean((a-b)^2 - s^2), clamped at
    // 0; relmse likewise with the weight w = 1/(b^2 + 1e-2), less the
    // first-order bias that the noise of w brings (4 (a-b) b s^2 w^2).
    // Without s these equal the raw values and ref_noise_rms is 0.
    bool has_ref_noise;
    double ref_noise_rms[4];        // sqrt(mean(s^2))
    double rmse_debiased[4];        // sqrt(max(0, mean((a-b)^2 - s^2)))
    double relmse_debiased[4];      // max(0, mean(((a-b)^2 - s^2) w - 4 (a-b) b s^2 w^2))
    double scaled_rmse_debiased[4]; // as rmse, for s a against b
} st_metrics;

bool st_image_compare(const st_image *a, const st_image *b, st_metrics *m, st_err *err);
// As st_image_compare, plus the debiased errors; b_stderr (same size, 3
// channels, may be NULL or empty) is the standard error of b's pixels.
bool st_image_compare_noisy(const st_image *a, const st_image *b, const st_image *b_stderr,
                            st_metrics *m, st_err *err);
// Whether the reference's noise is large against the error it measures:
// ref_noise_rms > rmse_debiased / 3 over all channels (false without noise data).
bool st_metrics_noise_dominates(const st_metrics *m);
// Heat map of |a - b| (mean over R,G,B) divided by its maximum and mapped
// to a black-blue-red-yellow-white ramp, 8-bit PNG, written atomically.
bool st_image_write_heatmap(const char *path, const st_image *a, const st_image *b, st_err *err);
// That ramp: t in [0, 1] (clamped) to 8-bit RGB, linear between the stops
// black, blue, red, yellow, white at t = 0, 1/4, 1/2, 3/4, 1.
void st_heat_colour(double t, uint8_t rgb[3]);

#ifdef __cplusplus
}
#endif
#endif
