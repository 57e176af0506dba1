// PNG output: exact sRGB encoding of known values, exposure, clamping, row
// order and channel layouts, decoded back with stb_image.
#include "st_test.h"
#include "st_image.h"
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

static void scratch(char *out, size_t n, const char *name) {
    snprintf(out, n, "%s/%s", ST_TEST_SCRATCH, name);
    unlink(out);
}

// Writes a 1-row grey-valued RGB image and returns its decoded R bytes.
static void encode_row(const char *name, const float *v, int n, float exposure, int *out) {
    char path[4096];
    scratch(path, sizeof path, name);
    st_err err = {0};
    st_image img;
    st_image_alloc(&img, n, 1, 3, &err);
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            st_image_px(&img, i, 0)[c] = v[i];
    CHECK(st_image_write_png(path, &img, exposure, &err), "%s: %s", name, err.msg);
    st_image_free(&img);
    int w = 0, h = 0, comp = 0;
    unsigned char *px = stbi_load(path, &w, &h, &comp, 0);
    CHECK(px && w == n && h == 1 && comp == 3, "%s: decoded %dx%d comp %d", name, w, h, comp);
    for (int i = 0; i < n; i++)
        out[i] = px && w == n ? px[3 * i] : -1;
    for (int i = 0; px && i < n; i++)
        CHECK(px[3 * i + 1] == px[3 * i] && px[3 * i + 2] == px[3 * i], "grey stays grey");
    stbi_image_free(px);
}

static void test_values(void) {
    // sRGB by hand: 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357 -> 187.52 -> 188;
    // 0.0031308 is the linear segment's end: 12.92 * 0.0031308 * 255 = 10.31 -> 10;
    // 0.2 -> 0.484529 * 255 = 123.55 -> 124; 0.04 -> 56.33 -> 56; 0.9 -> 243.45 -> 243;
    // 1e-4 -> 12.92e-4 * 255 = 0.33 -> 0; out of range values clamp.
    const float v[] = {0.5f, 0.0031308f, 1.0f, 0.2f, 0.04f, 0.9f, 1e-4f, 0.0f, 2.0f, -1.0f};
    const int want[] = {188, 10, 255, 124, 56, 243, 0, 0, 255, 0};
    int got[10];
    encode_row("values.png", v, 10, 0.0f, got);
    for (int i = 0; i < 10; i++)
        CHECK(got[i] == want[i], "linear %g -> %d, expected %d", v[i], got[i], want[i]);

    // Exposure +1 doubles, -1 halves: 0.25 * 2 -> 188, 1.0 / 2 -> 188,
    // 0.6 * 2 clamps to 255.
    const float e[] = {0.25f, 0.1f, 0.6f};
    int up[3], down[3];
    encode_row("exposure_up.png", e, 3, 1.0f, up);
    CHECK(up[0] == 188 && up[1] == 124 && up[2] == 255, "exposure +1: %d %d %d", up[0], up[1],
          up[2]);
    const float d[] = {1.0f, 0.4f, 0.0062616f};
    encode_row("exposure_down.png", d, 3, -1.0f, down);
    CHECK(down[0] == 188 && down[1] == 124 && down[2] == 10, "exposure -1: %d %d %d", down[0],
          down[1], down[2]);

    CHECK_REL(st_srgb_encode(0.5), 0.735356983, 1e-8, 0);
    CHECK_REL(st_srgb_encode(0.0031308), 0.0404499, 1e-5, 0);
    // The two pieces meet at the threshold (continuity to ~1e-7).
    CHECK(fabs(12.92 * 0.0031308 - (1.055 * pow(0.0031308, 1 / 2.4) - 0.055)) < 1e-6,
          "pieces meet");
    CHECK(st_srgb_encode(NAN) == 0.0 && st_srgb_encode(5) == 1.0, "clamps");
}

static void test_layout(void) {
    char path[4096];
    st_err err = {0};
    st_image img;
    // 2x2 RGB with distinct rows: row 0 is the top of the PNG.
    scratch(path, sizeof path, "rows.png");
    st_image_alloc(&img, 2, 2, 3, &err);
    st_image_px(&img, 0, 0)[0] = 1.0f; // top-left red
    st_image_px(&img, 1, 0)[1] = 1.0f; // top-right green
    st_image_px(&img, 0, 1)[2] = 1.0f; // bottom-left blue
    CHECK(st_image_write(path, &img, 0, &err), "%s", err.msg);
    int w, h, comp;
    unsigned char *px = stbi_load(path, &w, &h, &comp, 0);
    CHECK(px && w == 2 && h == 2 && comp == 3, "rows: %dx%d comp %d", w, h, comp);
    if (px) {
        CHECK(px[0] == 255 && px[1] == 0 && px[2] == 0, "top-left red");
        CHECK(px[3] == 0 && px[4] == 255 && px[5] == 0, "top-right green");
        CHECK(px[6] == 0 && px[7] == 0 && px[8] == 255, "bottom-left blue");
        CHECK(px[9] == 0 && px[10] == 0 && px[11] == 0, "bottom-right black");
    }
    stbi_image_free(px);
    st_image_free(&img);

    // RGBA: alpha is clamped, not sRGB-encoded or exposed (0.5 -> 127.5 -> 128).
    scratch(path, sizeof path, "rgba.png");
    st_image_alloc(&img, 1, 1, 4, &err);
    float *p = st_image_px(&img, 0, 0);
    p[0] = p[1] = p[2] = 0.25f;
    p[3] = 0.5f;
    CHECK(st_image_write_png(path, &img, 1.0f, &err), "%s", err.msg);
    px = stbi_load(path, &w, &h, &comp, 0);
    CHECK(px && comp == 4 && px[0] == 188 && px[3] == 128, "rgba: comp %d %d %d", comp,
          px ? px[0] : -1, px ? px[3] : -1);
    stbi_image_free(px);
    st_image_free(&img);

    // One channel -> grey PNG.
    scratch(path, sizeof path, "grey.png");
    st_image_alloc(&img, 3, 1, 1, &err);
    img.data[0] = 0.5f;
    img.data[1] = 0.2f;
    CHECK(st_image_write_png(path, &img, 0, &err), "%s", err.msg);
    px = stbi_load(path, &w, &h, &comp, 0);
    CHECK(px && comp == 1 && px[0] == 188 && px[1] == 124 && px[2] == 0, "grey");
    stbi_image_free(px);

    // Refusals leave no file: NaN, non-finite exposure, missing directory.
    img.data[2] = NAN;
    scratch(path, sizeof path, "nan.png");
    CHECK(!st_image_write_png(path, &img, 0, &err) && err.kind == ST_ERR_RUNTIME &&
              strstr(err.msg, path) && strstr(err.msg, "1 non-finite"),
          "NaN: %s", err.msg);
    CHECK(!st_test_exists(path), "no NaN png");
    img.data[2] = 0;
    CHECK(!st_image_write_png(path, &img, INFINITY, &err) && err.kind == ST_ERR_INPUT,
          "inf exposure: %s", err.msg);
    CHECK(!st_test_exists(path), "no png for bad exposure");
    snprintf(path, sizeof path, "%s/missing-dir/x.png", ST_TEST_SCRATCH);
    CHECK(!st_image_write_png(path, &img, 0, &err) && err.kind == ST_ERR_RUNTIME &&
              strstr(err.msg, path),
          "missing dir: %s", err.msg);
    st_image_free(&img);
}

int main(void) {
    test_values();
    test_layout();
    return st_test_summary("test_image_png");
}
