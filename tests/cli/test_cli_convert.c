// `strahl compare --heatmap` and `strahl convert`: the heat map's colour bar,
// its values and scale (--scale, the PNG's tEXt chunks); convert's tone maps
// against their published formulas, clamp against render's own PNG writer,
// the false-colour mode on the heat map's ramp; bad input: exit 2 naming the
// culprit, no output, the input never overwritten.
#include "st_test.h"
#include "st_base.h"
#include "st_image.h"
#include <math.h>
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

static char dir[4096];

static void path_of(char *out, size_t n, const char *name) {
    snprintf(out, n, "%s/%s", dir, name);
}

// A 1-row RGB EXR of grey values v (all three channels, or R only when red_only).
static void write_row(const char *name, const float *v, int n, bool red_only) {
    st_image img = {0};
    st_err err = {0};
    char path[4200];
    path_of(path, sizeof path, name);
    CHECK(st_image_alloc(&img, n, 1, 3, &err), "%s", err.msg);
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            img.data[3 * i + c] = red_only && c ? 0.0f : v[i];
    CHECK(st_image_write_exr(path, &img, &err), "%s", err.msg);
    st_image_free(&img);
}

static unsigned char *load(const char *name, int *w, int *h) {
    char path[4200];
    path_of(path, sizeof path, name);
    int comp = 0;
    unsigned char *px = stbi_load(path, w, h, &comp, 3);
    CHECK(px != NULL, "%s: not a PNG", name);
    return px;
}

// The value of tEXt chunk `key` of a PNG ("" when absent).
static void png_text(const char *name, const char *key, char *out, size_t n) {
    char path[4200];
    path_of(path, sizeof path, name);
    size_t len = 0;
    st_err err = {0};
    unsigned char *b = (unsigned char *)st_read_file(path, &len, &err);
    out[0] = 0;
    for (size_t i = 8; b && i + 12 <= len;) {
        size_t cl = (size_t)b[i] << 24 | (size_t)b[i + 1] << 16 | (size_t)b[i + 2] << 8 | b[i + 3];
        if (i + 12 + cl > len) break;
        if (!memcmp(b + i + 4, "tEXt", 4) && !strcmp((char *)b + i + 8, key)) {
            size_t kl = strlen(key) + 1;
            snprintf(out, n, "%.*s", (int)(cl - kl), (char *)b + i + 8 + kl);
        }
        i += 12 + cl;
    }
    free(b);
}

static bool rgb_is(const unsigned char *p, int r, int g, int b) {
    return p[0] == r && p[1] == g && p[2] == b;
}

// Ink (white) pixels in the label rows of the legend below a picture of height h.
static int label_ink(const unsigned char *px, int w, int h) {
    int n = 0;
    for (int y = h + 14; y < h + 21; y++)
        for (int x = 0; x < w; x++)
            n += rgb_is(px + 3 * ((size_t)y * w + x), 255, 255, 255);
    return n;
}

static void test_heatmap(void) {
    // |A - B| = 0, 1, 2, 4 against a black B.
    const float a[4] = {0, 1, 2, 4}, z[4] = {0, 0, 0, 0};
    write_row("a.exr", a, 4, false);
    write_row("z.exr", z, 4, false);
    const char *runs[3] = {"", "--scale 8", "--scale 2"};
    const char *outs[3] = {"h4.png", "h8.png", "h2.png"};
    for (int r = 0; r < 3; r++)
        CHECK(st_test_sh("cd '%s' && '%s' compare a.exr z.exr --heatmap %s %s > /dev/null", dir,
                         ST_TEST_STRAHL, outs[r], runs[r]) == 0,
              "compare --heatmap %s", runs[r]);
    int w = 0, h = 0;
    unsigned char *p4 = load("h4.png", &w, &h);
    CHECK(w == 96 && h == 1 + 24, "heat map with legend is %dx%d, want 96x25", w, h);
    if (p4 && w == 96 && h == 25) {
        // Scale 4 (the largest difference): 0 black, 1 blue, 2 red, 4 white.
        CHECK(rgb_is(p4, 0, 0, 0) && rgb_is(p4 + 3, 0, 0, 255) && rgb_is(p4 + 6, 255, 0, 0) &&
                  rgb_is(p4 + 9, 255, 255, 255),
              "heat map pixels");
        // The bar, row 1 + 5: black at its left end (x 3), white at its right (x 92).
        const unsigned char *bar = p4 + 3 * (6 * 96);
        CHECK(rgb_is(bar + 9, 0, 0, 0) && rgb_is(bar + 3 * 92, 255, 255, 255), "colour bar ends");
        CHECK(label_ink(p4, w, 1) > 10, "no values drawn under the bar");
    }
    unsigned char *p8 = load("h8.png", &w, &h);
    if (p4 && p8 && w == 96 && h == 25) {
        // Scale 8: 2 is a quarter (blue), 4 a half (red); the labels change.
        CHECK(rgb_is(p8 + 6, 0, 0, 255) && rgb_is(p8 + 9, 255, 0, 0), "--scale 8 pixels");
        CHECK(memcmp(p4 + 3 * 96 * 15, p8 + 3 * 96 * 15, 3 * 96 * 7) != 0,
              "the bar's values do not change with the scale");
    }
    char v[256];
    png_text("h4.png", "strahl.scale", v, sizeof v);
    CHECK(!strcmp(v, "4"), "h4 strahl.scale '%s'", v);
    png_text("h8.png", "strahl.scale", v, sizeof v);
    CHECK(!strcmp(v, "8"), "h8 strahl.scale '%s'", v);
    png_text("h2.png", "strahl.pixels_above_scale", v, sizeof v);
    CHECK(!strcmp(v, "1"), "h2 pixels above the scale '%s'", v);
    png_text("h2.png", "strahl.max", v, sizeof v);
    CHECK(!strcmp(v, "4"), "h2 strahl.max '%s'", v);
    stbi_image_free(p4);
    stbi_image_free(p8);
    const char *bad[] = {"--scale 0", "--scale -1", "--scale nan", "--scale 1e999", "--scale x"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECK(st_test_sh("cd '%s' && '%s' compare a.exr z.exr --heatmap bad.png %s", dir,
                         ST_TEST_STRAHL, bad[i]) == 2,
              "%s accepted", bad[i]);
    CHECK(st_test_sh("cd '%s' && '%s' compare a.exr z.exr --scale 2", dir, ST_TEST_STRAHL) == 2,
          "--scale without --heatmap accepted");
    char path[4200];
    path_of(path, sizeof path, "bad.png");
    CHECK(!st_test_exists(path), "bad.png written");
}

// The published curves, written out here independently of tools/cmd_convert.c.
static double aces(double x) {
    return fmin(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 1.0);
}
static double hable(double x) {
    return (x * (0.15 * x + 0.05) + 0.004) / (x * (0.15 * x + 0.5) + 0.06) - 0.02 / 0.3;
}
static int to8(double v) {
    return (int)floor(st_srgb_encode(v) * 255.0 + 0.5);
}

static void test_tonemaps(void) {
    const float v[6] = {0, 0.25f, 0.5f, 1, 4, 11.2f};
    write_row("c.exr", v, 6, false);
    CHECK(st_test_sh("cd '%s' && '%s' convert c.exr -o clamp.png --exposure 1", dir,
                     ST_TEST_STRAHL) == 0,
          "convert clamp");
    CHECK(st_test_sh("cd '%s' && '%s' convert c.exr -o aces.png --exposure 1 --tonemap aces", dir,
                     ST_TEST_STRAHL) == 0,
          "convert aces");
    CHECK(st_test_sh("cd '%s' && '%s' convert c.exr -o filmic.png --tonemap filmic", dir,
                     ST_TEST_STRAHL) == 0,
          "convert filmic");
    // clamp is exactly what render writes for -o OUT.png --exposure 1.
    st_image img = {0};
    st_err err = {0};
    char path[4200];
    path_of(path, sizeof path, "c.exr");
    CHECK(st_image_read_exr(path, &img, &err), "%s", err.msg);
    path_of(path, sizeof path, "render.png");
    CHECK(st_image_write_png(path, &img, 1.0f, &err), "%s", err.msg);
    st_image_free(&img);
    int w, h, w2, h2;
    unsigned char *pc = load("clamp.png", &w, &h), *pr = load("render.png", &w2, &h2);
    CHECK(pc && pr && w == 6 && h == 1 && w2 == 6 && !memcmp(pc, pr, 18),
          "clamp differs from render's PNG");
    unsigned char *pa = load("aces.png", &w, &h), *pf = load("filmic.png", &w2, &h2);
    for (int i = 0; pa && pf && w == 6 && w2 == 6 && i < 6; i++) {
        int wa = to8((float)aces(v[i] * 2.0)), wf = to8((float)(hable(v[i]) / hable(11.2)));
        CHECK(pa[3 * i] == wa && pa[3 * i + 2] == wa, "aces(%g): %d, want %d", v[i] * 2.0,
              pa[3 * i], wa);
        CHECK(pf[3 * i] == wf && pf[3 * i + 1] == wf, "filmic(%g): %d, want %d", v[i], pf[3 * i],
              wf);
    }
    // Anchors: aces(2) = 10.1 / 11.04 = 0.915; filmic reaches white at 11.2 only.
    CHECK(pa && pa[9] == to8(10.1 / 11.04), "aces(2) %d", pa ? pa[9] : -1);
    CHECK(pf && pf[15] == 255 && pf[12] < 255, "filmic white point");
    stbi_image_free(pc);
    stbi_image_free(pr);
    stbi_image_free(pa);
    stbi_image_free(pf);
}

static void test_false_colour(void) {
    // Luminance 0, 0.5, 1, 2, 4 (grey, so Y = v) on the heat map's ramp, scale 4.
    const float v[5] = {0, 0.5f, 1, 2, 4};
    write_row("y.exr", v, 5, false);
    CHECK(st_test_sh("cd '%s' && '%s' convert y.exr -o fc.png --false-colour --scale 4", dir,
                     ST_TEST_STRAHL) == 0,
          "convert --false-colour");
    int w, h;
    unsigned char *p = load("fc.png", &w, &h);
    CHECK(w == 96 && h == 25, "false colour with legend %dx%d", w, h);
    if (p && w == 96 && h == 25) {
        CHECK(rgb_is(p, 0, 0, 0) && rgb_is(p + 3, 0, 0, 128) && rgb_is(p + 6, 0, 0, 255) &&
                  rgb_is(p + 9, 255, 0, 0) && rgb_is(p + 12, 255, 255, 255),
              "false colour pixels");
        CHECK(label_ink(p, w, 1) > 10, "no values under the bar");
    }
    stbi_image_free(p);
    char s[256];
    png_text("fc.png", "strahl.scale", s, sizeof s);
    CHECK(!strcmp(s, "4"), "strahl.scale '%s'", s);
    png_text("fc.png", "strahl.quantity", s, sizeof s);
    CHECK(strstr(s, "luminance") != NULL, "strahl.quantity '%s'", s);
}

// Exit 2, the culprit named in the one message, no output file.
static void bad(const char *args, const char *culprit) {
    char out[8192], cmd[8192];
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' convert %s", dir, ST_TEST_STRAHL, args);
    int rc = st_test_capture(out, sizeof out, cmd);
    CHECK(rc == 2 && strstr(out, culprit) && strchr(out, '\n') == out + strlen(out) - 1,
          "convert %s: exit %d, '%s' (want exit 2 naming '%s')", args, rc, out, culprit);
    char path[4200];
    path_of(path, sizeof path, "bad.png");
    CHECK(!st_test_exists(path), "convert %s wrote bad.png", args);
}

static void test_bad_input(void) {
    char path[4200];
    path_of(path, sizeof path, "text.exr");
    FILE *f = fopen(path, "w");
    fputs("not an EXR\n", f);
    fclose(f);
    bad("missing.exr -o bad.png", "missing.exr");
    bad("text.exr -o bad.png", "text.exr");
    bad("c.exr -o bad.png --tonemap reinhard", "reinhard");
    bad("c.exr -o bad.png --exposure nan", "nan");
    bad("c.exr -o bad.png --exposure 100", "100");
    bad("c.exr -o bad.png --false-colour --exposure 1", "--exposure");
    bad("c.exr -o bad.png --scale 2", "--scale");
    bad("c.exr -o bad.jpg", "bad.jpg");
    bad("c.exr", "usage");
    // The input itself, by its name or through a hard link: refused, untouched.
    size_t before = 0, after = 0;
    st_err err = {0};
    path_of(path, sizeof path, "c.exr");
    free(st_read_file(path, &before, &err));
    bad("c.exr -o c.exr", "c.exr");
    char link_path[4200];
    path_of(link_path, sizeof link_path, "c.png");
    unlink(link_path);
    CHECK(link(path, link_path) == 0, "link");
    bad("c.exr -o c.png", "c.png");
    free(st_read_file(path, &after, &err));
    CHECK(before > 0 && before == after, "the input changed: %zu -> %zu bytes", before, after);
}

// --help on stdout, exit 0, naming every option (cli_help's list of
// commands predates convert), a default and an example.
static void test_help(void) {
    char out[8192], cmd[4400];
    snprintf(cmd, sizeof cmd, "'%s' convert --help 2>/dev/null", ST_TEST_STRAHL);
    CHECK(st_test_capture(out, sizeof out, cmd) == 0, "convert --help");
    const char *want[] = {
        "usage: strahl convert", "-o OUT.png", "--exposure", "--tonemap", "aces", "filmic",
        "--false-colour",        "--scale",    "default",    "example"};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        CHECK(strstr(out, want[i]) != NULL, "convert --help lacks '%s'", want[i]);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    test_help();
    test_heatmap();
    test_tonemaps();
    test_false_colour();
    test_bad_input();
    return st_test_summary("cli_convert");
}
