#include "false_colour.h"
#include "st_image.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// 5x7 glyphs of what "%.2g" prints (rows top first, bit 4 the left column).
static const char glyph_chars[] = "0123456789.-+e";
static const uint8_t glyphs[][7] = {
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}, {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00},
    {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}, {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E},
};
#define GLYPH_ADVANCE 6
static const uint8_t background[3] = {48, 48, 48}, ink[3] = {255, 255, 255};

typedef struct {
    uint8_t *px;
    int w, h;
} canvas;

static void put(const canvas *c, int x, int y, const uint8_t rgb[3]) {
    if (x < 0 || y < 0 || x >= c->w || y >= c->h) return;
    memcpy(c->px + 3 * ((size_t)y * c->w + x), rgb, 3);
}

static void text(const canvas *c, int x, int y, const char *s) {
    for (; *s; s++, x += GLYPH_ADVANCE) {
        const char *g = strchr(glyph_chars, *s);
        if (!g) continue;
        for (int r = 0; r < 7; r++)
            for (int b = 0; b < 5; b++)
                if (glyphs[g - glyph_chars][r] & (0x10 >> b)) put(c, x + b, y + r, ink);
    }
}

// The strip below the picture: the bar from 0 to the scale, ticks and the
// values at 2, 3 or 5 evenly spaced points (as many as fit).
static void legend(const canvas *c, int top, double scale) {
    for (int y = top; y < c->h; y++)
        for (int x = 0; x < c->w; x++)
            put(c, x, y, background);
    const int x0 = 3, x1 = c->w - 4;
    for (int x = x0; x <= x1; x++) {
        uint8_t rgb[3];
        st_heat_colour((double)(x - x0) / (x1 - x0), rgb);
        for (int y = top + 3; y < top + 11; y++)
            put(c, x, y, rgb);
    }
    const int nlab = c->w >= 320 ? 5 : c->w >= 160 ? 3 : 2;
    for (int k = 0; k < nlab; k++) {
        double t = (double)k / (nlab - 1);
        int x = x0 + (int)lround(t * (x1 - x0));
        put(c, x, top + 11, ink);
        put(c, x, top + 12, ink);
        char label[32];
        snprintf(label, sizeof label, "%.2g", t * scale);
        int lw = (int)strlen(label) * GLYPH_ADVANCE - 1;
        int lx = x - lw / 2;
        lx = lx < 1 ? 1 : lx + lw > c->w - 1 ? c->w - 1 - lw : lx;
        text(c, lx, top + 14, label);
    }
}

double st_false_colour_max(const double *v, size_t n) {
    double m = 0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(v[i]) && v[i] > m) m = v[i];
    return m;
}

bool st_write_false_colour(const char *path, const double *v, int w, int h,
                           const st_false_colour *fc, st_err *err) {
    if (!(fc->scale > 0) || !isfinite(fc->scale))
        return st_fail(err, ST_ERR_INPUT, "%s: scale %g: expected a positive finite number", path,
                       fc->scale);
    canvas c = {NULL, w > ST_LEGEND_MIN_WIDTH ? w : ST_LEGEND_MIN_WIDTH, h + ST_LEGEND_ROWS};
    c.px = calloc((size_t)c.w * c.h, 3);
    if (!c.px) return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    legend(&c, h, fc->scale);
    size_t above = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < c.w; x++) {
            uint8_t rgb[3];
            const double d = x < w ? v[(size_t)y * w + x] : 0;
            above += d > fc->scale;
            if (x < w) st_heat_colour(d / fc->scale, rgb);
            put(&c, x, y, x < w ? rgb : background);
        }
    char scale[32], max[32], nabove[32];
    snprintf(scale, sizeof scale, "%.9g", fc->scale);
    snprintf(max, sizeof max, "%.9g", st_false_colour_max(v, (size_t)w * h));
    snprintf(nabove, sizeof nabove, "%zu", above);
    const char *const meta[] = {"Software",
                                "strahl",
                                "strahl.quantity",
                                fc->quantity,
                                "strahl.scale",
                                scale,
                                "strahl.max",
                                max,
                                "strahl.pixels_above_scale",
                                nabove,
                                "strahl.colormap",
                                "value/scale: 0 black, 1/4 blue, 1/2 red, 3/4 yellow, 1 and above "
                                "white, linear between",
                                "strahl.legend",
                                "the bottom 24 rows: the colour bar from 0 to the scale with its "
                                "values",
                                NULL};
    bool ok = st_png_write8_text(path, c.px, c.w, c.h, 3, meta, err);
    free(c.px);
    return ok;
}
