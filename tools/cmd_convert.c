// strahl convert IN.exr -o OUT.png [--exposure EV] [--tonemap clamp|aces|filmic]
//                                  [--false-colour [--scale MAX]]
// An EXR (a still of render, reference or merge) as an 8-bit sRGB PNG, with
// an exposure and a tone map, or its luminance in the heat map's false
// colour with the same legend (tools/false_colour.h).
#include "cmd_common.h"
#include "false_colour.h"
#include "st_cmd.h"
#include "st_file.h"
#include "st_image.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char help_text[] =
    "usage: strahl convert IN.exr -o OUT.png [--exposure EV] [--tonemap clamp|aces|filmic] "
    "[--false-colour [--scale MAX]]\n"
    "An EXR as an 8-bit sRGB PNG: each channel x = value * 2^EV goes through the tone map,\n"
    "then the sRGB curve (alpha is clamped only). The input is never overwritten.\n"
    "  -o OUT.png           output (required; written atomically)\n"
    "  --exposure EV        scale by 2^EV first, -64..64 (default 0)\n"
    "  --tonemap T          clamp: min(x, 1), what render -o OUT.png writes (default);\n"
    "                       aces: Narkowicz's fit of the ACES film curve,\n"
    "                       x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped;\n"
    "                       filmic: Hable's Uncharted 2 curve with white point 11.2\n"
    "  --false-colour       the luminance Y = 0.2126 R + 0.7152 G + 0.0722 B in the colour\n"
    "                       map of compare --heatmap (black 0, blue 1/4, red 1/2, yellow\n"
    "                       3/4, white the scale and above) with its colour bar and values\n"
    "                       below; no --exposure or --tonemap with it\n"
    "  --scale MAX          the luminance drawn white (default: the largest)\n"
    "  -h, --help           this text (docs/images.md has the curves and the colour map)\n"
    "example:\n"
    "  strahl convert ref.exr -o ref.png --exposure 2 --tonemap aces\n";

typedef enum { TM_CLAMP, TM_ACES, TM_FILMIC } tonemap;

typedef struct convert_args {
    const char *in, *out;
    double exposure, scale;
    tonemap tm;
    bool false_colour, exposure_set, tonemap_set;
} convert_args;

static bool parse_number(const char *flag, const char *v, double lo, double hi, double *out,
                         st_err *err) {
    char *e;
    *out = strtod(v, &e);
    if (e == v || *e || !isfinite(*out) || *out < lo || *out > hi)
        return st_fail(err, ST_ERR_INPUT, "%s %s: expected a number in %g..%g", flag, v, lo, hi);
    return true;
}

static bool parse_option(convert_args *a, const char *o, const char *v, st_err *err) {
    if (!strcmp(o, "-o")) {
        a->out = v;
    } else if (!strcmp(o, "--exposure")) {
        a->exposure_set = true;
        return parse_number(o, v, -64, 64, &a->exposure, err);
    } else if (!strcmp(o, "--scale")) {
        if (!parse_number(o, v, 0, INFINITY, &a->scale, err)) return false;
        if (!(a->scale > 0)) return st_fail(err, ST_ERR_INPUT, "--scale %s: expected > 0", v);
    } else if (!strcmp(o, "--tonemap")) {
        a->tonemap_set = true;
        if (!strcmp(v, "clamp"))
            a->tm = TM_CLAMP;
        else if (!strcmp(v, "aces"))
            a->tm = TM_ACES;
        else if (!strcmp(v, "filmic"))
            a->tm = TM_FILMIC;
        else
            return st_fail(err, ST_ERR_INPUT, "--tonemap %s: expected clamp, aces or filmic", v);
    }
    return true;
}

// Fills a; *help: the text was printed.
static bool parse_args(convert_args *a, int argc, char **argv, bool *help, st_err *err) {
    *help = false;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(help_text, stdout);
            *help = true;
            return true;
        } else if (!strcmp(o, "--false-colour")) {
            a->false_colour = true;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--exposure") || !strcmp(o, "--scale") ||
                   !strcmp(o, "--tonemap")) {
            if (i + 1 >= argc) return st_fail(err, ST_ERR_INPUT, "%s: missing value", o);
            if (!parse_option(a, o, argv[++i], err)) return false;
        } else if ((o[0] == '-' && o[1]) || a->in) {
            return st_fail(err, ST_ERR_INPUT,
                           "unexpected argument '%s' (see strahl convert --help)", o);
        } else {
            a->in = o;
        }
    }
    if (!a->in || !a->out)
        return st_fail(err, ST_ERR_INPUT,
                       "usage: strahl convert IN.exr -o OUT.png [--exposure EV] [--tonemap "
                       "clamp|aces|filmic] [--false-colour [--scale MAX]]");
    if (a->false_colour && (a->exposure_set || a->tonemap_set))
        return st_fail(err, ST_ERR_INPUT,
                       "--false-colour maps the luminance itself: no --exposure or --tonemap");
    if (a->scale > 0 && !a->false_colour)
        return st_fail(err, ST_ERR_INPUT, "--scale is for --false-colour");
    return true;
}

static double hable(double x) {
    const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

// The tone map of x >= 0, into [0, 1].
static double tone(tonemap tm, double x) {
    x = fmax(x, 0.0);
    if (tm == TM_ACES) return fmin((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 1.0);
    if (tm == TM_FILMIC) return fmin(hable(x) / hable(11.2), 1.0);
    return fmin(x, 1.0);
}

// The tone-mapped image written through st_image_write_png at exposure 0, so
// the sRGB encoding is exactly render's; clamp is render's PNG itself.
static bool write_tonemapped(const convert_args *a, st_image *img, st_err *err) {
    if (a->tm == TM_CLAMP) return st_image_write_png(a->out, img, (float)a->exposure, err);
    const double k = exp2(a->exposure);
    const int nc = img->channels, ncol = nc >= 3 ? 3 : 1;
    const size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < ncol; c++)
            img->data[i * nc + c] = (float)tone(a->tm, img->data[i * nc + c] * k);
    return st_image_write_png(a->out, img, 0.0f, err);
}

static bool write_false_colour(const convert_args *a, const st_image *img, st_err *err) {
    const size_t n = (size_t)img->width * img->height;
    double *y = malloc(n * sizeof *y);
    if (!y) return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", a->out);
    for (size_t i = 0; i < n; i++) {
        const float *p = img->data + i * img->channels;
        y[i] = img->channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
    }
    st_false_colour fc = {.quantity = "luminance 0.2126 R + 0.7152 G + 0.0722 B",
                          .scale = a->scale};
    if (!(fc.scale > 0)) fc.scale = fmax(st_false_colour_max(y, n), 1e-12);
    bool ok = st_write_false_colour(a->out, y, img->width, img->height, &fc, err);
    free(y);
    return ok;
}

int st_cmd_convert(int argc, char **argv) {
    convert_args a = {.tm = TM_CLAMP};
    st_err err = {0};
    bool help;
    if (!parse_args(&a, argc, argv, &help, &err)) return st_report("convert", &err);
    if (help) return ST_EXIT_OK;
    static const char *const exts[] = {"png", NULL};
    const char *inputs[] = {a.in, NULL};
    if (!st_check_output("-o", a.out, exts, inputs, &err)) return st_report("convert", &err);
    st_image img = {0};
    bool ok = st_image_read_exr(a.in, &img, &err);
    if (!ok) err.kind = ST_ERR_INPUT; // an unreadable EXR is bad input, named by the reader
    size_t bad = ok ? st_image_count_nonfinite(&img) : 0;
    if (bad) ok = st_fail(&err, ST_ERR_INPUT, "%s: %zu non-finite values (NaN or Inf)", a.in, bad);
    if (ok)
        ok = a.false_colour ? write_false_colour(&a, &img, &err) : write_tonemapped(&a, &img, &err);
    st_image_free(&img);
    return ok ? ST_EXIT_OK : st_report("convert", &err);
}
