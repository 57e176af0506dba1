// st_image_compare and the heat map on small constructed images whose
// metrics are worked out by hand.
#include "st_test.h"
#include "st_image.h"
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

// 2x2 RGB from per-channel arrays of 4 pixels (row-major, top row first).
static st_image make(const float r[4], const float g[4], const float b[4]) {
    st_image img;
    st_err err = {0};
    st_image_alloc(&img, 2, 2, 3, &err);
    for (int k = 0; k < 4; k++) {
        img.data[3 * k] = r[k];
        img.data[3 * k + 1] = g[k];
        img.data[3 * k + 2] = b[k];
    }
    return img;
}

static void test_hand_computed(void) {
    // Reference b: R = 1 2 3 4, G = 0, B = 2. Image a differs by +2 in R of
    // the last pixel and +0.5 in G of the second.
    const float bR[4] = {1, 2, 3, 4}, bG[4] = {0, 0, 0, 0}, bB[4] = {2, 2, 2, 2};
    const float aR[4] = {1, 2, 3, 6}, aG[4] = {0, 0.5f, 0, 0};
    st_image a = make(aR, aG, bB), b = make(bR, bG, bB);
    st_metrics m;
    st_err err = {0};
    CHECK(st_image_compare(&a, &b, &m, &err), "%s", err.msg);
    // rmse: R sqrt(4/4) = 1, G sqrt(0.25/4) = 0.25, B 0, all sqrt(4.25/12).
    CHECK_REL(m.rmse[0], 1.0, 1e-12, 0);
    CHECK_REL(m.rmse[1], 0.25, 1e-12, 0);
    CHECK(m.rmse[2] == 0.0, "rmse B %g", m.rmse[2]);
    CHECK_REL(m.rmse[3], 0.5951190357119042, 1e-12, 0);
    // relmse: R 4/(16 + 0.01)/4, G 0.25/(0 + 0.01)/4 = 6.25, all (4/16.01 + 25)/12.
    CHECK_REL(m.relmse[0], 0.062460961898813235, 1e-12, 0);
    CHECK_REL(m.relmse[1], 6.25, 1e-12, 0);
    CHECK(m.relmse[2] == 0.0, "relmse B");
    CHECK_REL(m.relmse[3], 2.104153653966271, 1e-12, 0);
    // psnr with peak max(b) = 4: R 20 log10(4) = 12.0412, G 20 log10(16), B inf.
    CHECK_REL(m.psnr[0], 12.041199826559248, 1e-12, 0);
    CHECK_REL(m.psnr[1], 24.082399653118497, 1e-12, 0);
    CHECK(isinf(m.psnr[2]) && m.psnr[2] > 0, "psnr B %g", m.psnr[2]);
    CHECK_REL(m.psnr[3], 16.54912298653238, 1e-12, 0);
    CHECK(m.max_abs[0] == 2.0 && m.max_abs[1] == 0.5 && m.max_abs[2] == 0 && m.max_abs[3] == 2.0,
          "max_abs %g %g %g %g", m.max_abs[0], m.max_abs[1], m.max_abs[2], m.max_abs[3]);
    // scale = sum ab / sum aa = (38 + 0 + 16) / (50 + 0.25 + 16) = 54 / 66.25.
    CHECK_REL(m.scale, 54.0 / 66.25, 1e-12, 0);
    CHECK_REL(m.scaled_rmse[0], 0.5638637497043831, 1e-12, 0);
    CHECK_REL(m.scaled_rmse[1], 0.2037735849056604, 1e-12, 0);
    CHECK_REL(m.scaled_rmse[2], 0.3698113207547169, 1e-12, 0);
    CHECK_REL(m.scaled_rmse[3], 0.40670481314025114, 1e-12, 0);
    // Means: a R 3, G 0.125, B 2, all 20.5/12; b R 2.5, G 0, B 2, all 1.5.
    CHECK_REL(m.mean_a[0], 3.0, 1e-12, 0);
    CHECK_REL(m.mean_a[1], 0.125, 1e-12, 0);
    CHECK_REL(m.mean_a[2], 2.0, 1e-12, 0);
    CHECK_REL(m.mean_a[3], 20.5 / 12, 1e-12, 0);
    CHECK_REL(m.mean_b[0], 2.5, 1e-12, 0);
    CHECK(m.mean_b[1] == 0.0, "mean_b G");
    CHECK_REL(m.mean_b[3], 1.5, 1e-12, 0);
    st_image_free(&a);
    st_image_free(&b);
}

static void test_special(void) {
    const float bR[4] = {1, 2, 3, 4}, bG[4] = {0.5f, 0.25f, 8, 1}, bB[4] = {2, 0, 2, 7};
    st_image b = make(bR, bG, bB), a;
    st_metrics m;
    st_err err = {0};

    // A scaled copy: the fitted scale undoes it exactly.
    st_image_alloc(&a, 2, 2, 3, &err);
    for (int k = 0; k < 12; k++)
        a.data[k] = 0.25f * b.data[k];
    CHECK(st_image_compare(&a, &b, &m, &err), "%s", err.msg);
    CHECK_REL(m.scale, 4.0, 1e-12, 0);
    CHECK(m.scaled_rmse[3] < 1e-12, "scaled rmse %g", m.scaled_rmse[3]);
    CHECK(m.rmse[3] > 1.0, "plain rmse %g", m.rmse[3]);
    // max_abs of the unscaled copy is 0.75 * max(b) = 6 (pixel 3 of G: 8 -> 2).
    CHECK_REL(m.max_abs[3], 6.0, 1e-12, 0);

    // Identical images: zero errors, infinite psnr, scale 1.
    CHECK(st_image_compare(&b, &b, &m, &err), "%s", err.msg);
    CHECK(m.rmse[3] == 0 && m.max_abs[3] == 0 && isinf(m.psnr[3]), "identical");
    CHECK_REL(m.scale, 1.0, 1e-12, 0);

    // All-zero a: scale 0, scaled rmse = rmse = rms of b.
    memset(a.data, 0, 12 * sizeof(float));
    CHECK(st_image_compare(&a, &b, &m, &err), "%s", err.msg);
    CHECK(m.scale == 0.0, "scale %g", m.scale);
    CHECK_REL(m.scaled_rmse[3], m.rmse[3], 1e-12, 0);
    CHECK_REL(m.rmse[0], sqrt(30.0 / 4), 1e-12, 0);

    // A grey (1-channel) image compares as R = G = B.
    st_image grey;
    st_image_alloc(&grey, 2, 2, 1, &err);
    for (int k = 0; k < 4; k++)
        grey.data[k] = bR[k];
    CHECK(st_image_compare(&grey, &b, &m, &err), "%s", err.msg);
    CHECK(m.rmse[0] == 0.0 && m.rmse[1] > 0, "grey R %g G %g", m.rmse[0], m.rmse[1]);
    st_image_free(&grey);

    // Errors: size mismatch names both sizes; NaN inputs refused.
    st_image wide;
    st_image_alloc(&wide, 3, 2, 3, &err);
    CHECK(!st_image_compare(&wide, &b, &m, &err) && err.kind == ST_ERR_INPUT &&
              strstr(err.msg, "3x2") && strstr(err.msg, "2x2"),
          "mismatch: %s", err.msg);
    char path[4096];
    snprintf(path, sizeof path, "%s/mismatch.png", ST_TEST_SCRATCH);
    unlink(path);
    CHECK(!st_image_write_heatmap(path, &wide, &b, &err) && err.kind == ST_ERR_INPUT,
          "heatmap mismatch: %s", err.msg);
    CHECK(!st_test_exists(path), "no heatmap on mismatch");
    st_image_free(&wide);
    a.data[5] = NAN;
    CHECK(!st_image_compare(&a, &b, &m, &err) && err.kind == ST_ERR_INPUT &&
              strstr(err.msg, "1 non-finite"),
          "NaN: %s", err.msg);
    st_image_free(&a);
    st_image_free(&b);
}

static void test_heatmap(void) {
    // |a - b| averaged over RGB: 0, 4 (the max), 2, 1 -> ramp positions 0, 1,
    // 1/2, 1/4 -> black, white, red, blue.
    const float z[4] = {0, 0, 0, 0};
    const float aR[4] = {0, 6, 3, 1}, aG[4] = {0, 3, 0, 1}, aB[4] = {0, 3, 3, 1};
    st_image a = make(aR, aG, aB), b = make(z, z, z);
    char path[4096];
    snprintf(path, sizeof path, "%s/heat.png", ST_TEST_SCRATCH);
    unlink(path);
    st_err err = {0};
    CHECK(st_image_write_heatmap(path, &a, &b, &err), "%s", err.msg);
    int w, h, comp;
    unsigned char *px = stbi_load(path, &w, &h, &comp, 0);
    CHECK(px && w == 2 && h == 2 && comp == 3, "heat map %dx%d comp %d", w, h, comp);
    if (px) {
        const int want[4][3] = {{0, 0, 0}, {255, 255, 255}, {255, 0, 0}, {0, 0, 255}};
        for (int k = 0; k < 4; k++)
            CHECK(px[3 * k] == want[k][0] && px[3 * k + 1] == want[k][1] &&
                      px[3 * k + 2] == want[k][2],
                  "pixel %d = %d %d %d", k, px[3 * k], px[3 * k + 1], px[3 * k + 2]);
    }
    stbi_image_free(px);
    // Identical images: an all-black map, no division by zero.
    CHECK(st_image_write_heatmap(path, &b, &b, &err), "%s", err.msg);
    px = stbi_load(path, &w, &h, &comp, 0);
    int sum = 0;
    for (int k = 0; px && k < 12; k++)
        sum += px[k];
    CHECK(px && sum == 0, "identical -> black (%d)", sum);
    stbi_image_free(px);
    st_image_free(&a);
    st_image_free(&b);
}

int main(void) {
    test_hand_computed();
    test_special();
    test_heatmap();
    return st_test_summary("test_image_metrics");
}
