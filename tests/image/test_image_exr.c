// EXR I/O: bit-exact float round trips, HALF files (scanline and tiled, as
// written by OpenEXRCore directly) converted to float with the top row first,
// named channels, and refused writes that leave no file behind.
#include "st_test.h"
#include "st_image.h"
#include <float.h>
#include <openexr.h>
#include <stdint.h>

static void scratch(char *out, size_t n, const char *name) {
    snprintf(out, n, "%s/%s", ST_TEST_SCRATCH, name);
    unlink(out);
}

static int tmp_left(const char *path) {
    char t[4300];
    snprintf(t, sizeof t, "%s.tmp-%ld", path, (long)getpid());
    return st_test_exists(t);
}

// Values from 1e-8 to 1e8 (log-spaced, mixed signs) plus the awkward floats:
// zero, -0, the smallest subnormal, FLT_MAX.
static void fill_wide(st_image *img) {
    size_t n = (size_t)img->width * img->height * img->channels;
    for (size_t i = 0; i < n; i++) {
        double t = n > 1 ? (double)i / (double)(n - 1) : 0.5;
        float v = (float)pow(10.0, -8.0 + 16.0 * t);
        img->data[i] = (i % 5 == 3) ? -v : v;
    }
    if (n > 4) {
        img->data[1] = 0.0f;
        img->data[2] = -0.0f;
        img->data[3] = FLT_TRUE_MIN;
        img->data[4] = FLT_MAX;
    }
}

static void roundtrip(const char *name, int w, int h, int c) {
    char path[4096];
    scratch(path, sizeof path, name);
    st_err err = {0};
    st_image img, back;
    CHECK(st_image_alloc(&img, w, h, c, &err), "alloc: %s", err.msg);
    fill_wide(&img);
    if (w * h * c == 3) { // 1x1 RGB: the extremes of the range
        img.data[0] = 1e-8f;
        img.data[1] = 1e8f;
        img.data[2] = -3.25f;
    }
    CHECK(st_image_write_exr(path, &img, &err), "%s: %s", name, err.msg);
    CHECK(!tmp_left(path), "%s: temporary file left", name);
    bool ok = st_image_read_exr(path, &back, &err);
    CHECK(ok, "%s: read: %s", name, err.msg);
    if (ok) {
        CHECK(back.width == w && back.height == h && back.channels == c, "%s: got %dx%dx%d", name,
              back.width, back.height, back.channels);
        size_t n = (size_t)w * h * c, diff = 0;
        if (back.width == w && back.height == h && back.channels == c)
            for (size_t i = 0; i < n; i++)
                diff += memcmp(&img.data[i], &back.data[i], 4) != 0;
        CHECK(diff == 0, "%s: %zu of %zu values not bit-exact", name, diff, n);
    }
    st_image_free(&back);
    st_image_free(&img);
}

// ---------------------------------------------------------------------------
// HALF files written with OpenEXRCore itself.

static double half_to_double(uint16_t h) {
    int s = h >> 15, e = (h >> 10) & 31, m = h & 1023;
    double v = e == 0 ? ldexp(m, -24) : ldexp(1024 + m, e - 25);
    return s ? -v : v;
}

// Finite half bit pattern of pixel (i, j) channel c: varied over the whole
// range (subnormals, negatives, up to 65504), never Inf/NaN.
static uint16_t half_pattern(int i, int j, int c) {
    uint16_t h = (uint16_t)((i * 131u + j * 977u + c * 7919u + 17u) & 0xFFFFu);
    if (((h >> 10) & 31) == 31) h &= (uint16_t) ~(1u << 14); // exponent 31 -> 15
    return h;
}

// Writes w x h pixels of `nc` HALF channels `names` (interleaved px, top row
// first) with the data window starting at (ox, oy).
static bool write_half_exr(const char *path, bool tiled, exr_compression_t comp, int w, int h,
                           int ox, int oy, int nc, const char *const *names, const uint16_t *px) {
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    if (exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init)) return false;
    int part = 0, tw = 8, th = 4;
    exr_attr_box2i_t dw;
    dw.min.x = ox;
    dw.min.y = oy;
    dw.max.x = ox + w - 1;
    dw.max.y = oy + h - 1;
    exr_attr_v2f_t swc;
    swc.x = swc.y = 0;
    bool ok = !exr_add_part(ctx, "", tiled ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, &part) &&
              !exr_initialize_required_attr(ctx, part, &dw, &dw, 1.f, &swc, 1.f,
                                            EXR_LINEORDER_INCREASING_Y, comp);
    if (ok && tiled)
        ok = !exr_set_tile_descriptor(ctx, part, tw, th, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN);
    for (int c = 0; ok && c < nc; c++)
        ok = !exr_add_channel(ctx, part, names[c], EXR_PIXEL_HALF, EXR_PERCEPTUALLY_LOGARITHMIC, 1,
                              1);
    ok = ok && !exr_write_header(ctx);
    int32_t lines = 1;
    if (ok && !tiled) ok = !exr_get_scanlines_per_chunk(ctx, part, &lines);
    int nx = tiled ? (w + tw - 1) / tw : 1,
        ny = tiled ? (h + th - 1) / th : (h + lines - 1) / lines;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool ready = false;
    for (int ty = 0; ok && ty < ny; ty++) {
        for (int tx = 0; ok && tx < nx; tx++) {
            exr_chunk_info_t ci;
            int x0 = tiled ? tx * tw : 0, y0 = tiled ? ty * th : ty * lines;
            ok = tiled ? !exr_write_tile_chunk_info(ctx, part, tx, ty, 0, 0, &ci)
                       : !exr_write_scanline_chunk_info(ctx, part, oy + y0, &ci);
            ok = ok && !(ready ? exr_encoding_update(ctx, part, &ci, &enc)
                               : exr_encoding_initialize(ctx, part, &ci, &enc));
            for (int k = 0; ok && k < enc.channel_count; k++) {
                int src = 0;
                for (int c = 0; c < nc; c++)
                    if (!strcmp(enc.channels[k].channel_name, names[c])) src = c;
                enc.channels[k].user_data_type = EXR_PIXEL_HALF;
                enc.channels[k].user_bytes_per_element = 2;
                enc.channels[k].user_pixel_stride = nc * 2;
                enc.channels[k].user_line_stride = w * nc * 2;
                enc.channels[k].encode_from_ptr =
                    (const uint8_t *)(px + ((size_t)y0 * w + x0) * nc + src);
            }
            if (ok && !ready) ok = !exr_encoding_choose_default_routines(ctx, part, &enc);
            ready = ready || ok;
            ok = ok && !exr_encoding_run(ctx, part, &enc);
        }
    }
    if (ready) exr_encoding_destroy(ctx, &enc);
    return !exr_finish(&ctx) && ok;
}

static void half_case(const char *name, bool tiled, exr_compression_t comp, int w, int h, int ox,
                      int oy, int nc, const char *const *names) {
    char path[4096];
    scratch(path, sizeof path, name);
    uint16_t *px = malloc(sizeof *px * w * h * nc);
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++)
            for (int c = 0; c < nc; c++)
                px[((size_t)j * w + i) * nc + c] = half_pattern(i, j, c);
    CHECK(write_half_exr(path, tiled, comp, w, h, ox, oy, nc, names, px),
          "%s: OpenEXRCore could not write the test file", name);
    st_err err = {0};
    st_image img;
    bool ok = st_image_read_exr(path, &img, &err);
    CHECK(ok, "%s: %s", name, err.msg);
    if (ok) {
        CHECK(img.width == w && img.height == h && img.channels == nc, "%s: got %dx%dx%d", name,
              img.width, img.height, img.channels);
        int bad = 0, first = -1;
        for (int j = 0; j < h && img.channels == nc; j++)
            for (int i = 0; i < w; i++)
                for (int c = 0; c < nc; c++) {
                    double want = half_to_double(px[((size_t)j * w + i) * nc + c]);
                    if ((double)st_image_px(&img, i, j)[c] != want) {
                        bad++;
                        if (first < 0) first = (j * w + i) * nc + c;
                    }
                }
        CHECK(bad == 0, "%s: %d values differ from the half values (first at %d)", name, bad,
              first);
        // Top row first: pixel (0,0) is the data window's first pixel.
        CHECK(st_image_px(&img, 0, 0)[0] == (float)half_to_double(half_pattern(0, 0, 0)),
              "%s: top-left pixel %g", name, st_image_px(&img, 0, 0)[0]);
    }
    st_image_free(&img);
    free(px);
}

static void test_half(void) {
    // The decoder used by the tests is itself checked on hand-computed halves.
    CHECK(half_to_double(0x3C00) == 1.0, "1.0");
    CHECK(half_to_double(0x3800) == 0.5, "0.5");
    CHECK(half_to_double(0xC000) == -2.0, "-2");
    CHECK(half_to_double(0x7BFF) == 65504.0, "max half");
    CHECK(half_to_double(0x0001) == 5.9604644775390625e-08, "smallest subnormal");
    CHECK(half_to_double(0x0400) == 6.103515625e-05, "smallest normal");
    CHECK(half_to_double(0x3555) == 0.333251953125, "1/3");
    CHECK(half_to_double(0x5640) == 100.0, "100");

    static const char *const rgb[] = {"R", "G", "B"}, *const rgba[] = {"R", "G", "B", "A"},
                             *const y[] = {"Y"};
    half_case("half_rgb_none.exr", false, EXR_COMPRESSION_NONE, 37, 19, 0, 0, 3, rgb);
    half_case("half_rgba_zip.exr", false, EXR_COMPRESSION_ZIP, 37, 19, 0, 0, 4, rgba);
    half_case("half_rgb_piz.exr", false, EXR_COMPRESSION_PIZ, 40, 35, 0, 0, 3, rgb);
    // Tiled, partial edge tiles, data window not at the origin, luminance only.
    half_case("half_y_tiled.exr", true, EXR_COMPRESSION_ZIP, 21, 11, 3, -2, 1, y);
    half_case("half_rgb_tiled.exr", true, EXR_COMPRESSION_NONE, 9, 5, 0, 0, 3, rgb);
}

// ---------------------------------------------------------------------------

static void test_named(void) {
    char path[4096];
    scratch(path, sizeof path, "named.exr");
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    st_err err = {0};
    st_image img, back;
    st_image_alloc(&img, 7, 3, 6, &err);
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 7; i++)
            for (int c = 0; c < 6; c++)
                st_image_px(&img, i, j)[c] = (float)(100 * c + 10 * j + i);
    CHECK(st_image_write_exr_named(path, &img, names, &err), "%s", err.msg);
    // st_image_read_exr picks R,G,B out of the six channels.
    bool ok = st_image_read_exr(path, &back, &err);
    CHECK(ok && back.channels == 3, "read RGB of a layered file: %s", err.msg);
    if (ok) {
        CHECK(st_image_px(&back, 6, 2)[2] == 226.f, "B(6,2) = %g", st_image_px(&back, 6, 2)[2]);
        CHECK(st_image_px(&back, 0, 1)[0] == 10.f, "R(0,1) = %g", st_image_px(&back, 0, 1)[0]);
    }
    st_image_free(&back);
    static const char *const want[] = {"stderr.B", "R"};
    ok = st_image_read_exr_channels(path, want, 2, &back, &err);
    CHECK(ok && back.channels == 2, "read named channels: %s", err.msg);
    if (ok) {
        CHECK(st_image_px(&back, 3, 2)[0] == 523.f, "stderr.B(3,2) = %g",
              st_image_px(&back, 3, 2)[0]);
        CHECK(st_image_px(&back, 3, 2)[1] == 23.f, "R(3,2) = %g", st_image_px(&back, 3, 2)[1]);
    }
    st_image_free(&back);
    static const char *const missing[] = {"R", "variance.R"};
    CHECK(!st_image_read_exr_channels(path, missing, 2, &back, &err), "missing channel read");
    CHECK(err.kind == ST_ERR_INPUT && strstr(err.msg, "variance.R") && strstr(err.msg, path),
          "missing channel message: %s", err.msg);
    // Duplicate names are refused before anything is written.
    static const char *const dup[] = {"R", "G", "B", "R", "x", "y"};
    char path2[4096];
    scratch(path2, sizeof path2, "dup.exr");
    CHECK(!st_image_write_exr_named(path2, &img, dup, &err) && err.kind == ST_ERR_INPUT,
          "duplicate channel names: %s", err.msg);
    CHECK(!st_test_exists(path2), "no file for duplicate names");
    // 6 channels without names: st_image_write_exr cannot guess them.
    CHECK(!st_image_write_exr(path2, &img, &err) && err.kind == ST_ERR_INPUT, "6 channels: %s",
          err.msg);
    st_image_free(&img);
}

static void test_refusals(void) {
    char path[4096], bad[4096];
    st_err err = {0};
    st_image img, back;
    st_image_alloc(&img, 4, 3, 3, &err);
    for (int k = 0; k < 36; k++)
        img.data[k] = 0.25f * k;

    // An existing good file survives a refused overwrite untouched.
    scratch(path, sizeof path, "keep.exr");
    CHECK(st_image_write(path, &img, 0, &err), "%s", err.msg);
    img.data[7] = NAN;
    img.data[20] = INFINITY;
    CHECK(!st_image_write_exr(path, &img, &err), "NaN write refused");
    CHECK(err.kind == ST_ERR_RUNTIME, "kind %d", err.kind);
    CHECK(strstr(err.msg, path) && strstr(err.msg, "2 non-finite"), "message: %s", err.msg);
    CHECK(!tmp_left(path), "no temporary file after refusal");
    CHECK(st_image_read_exr(path, &back, &err) && back.data[7] == 1.75f, "old file intact: %s",
          err.msg);
    st_image_free(&back);

    scratch(bad, sizeof bad, "nan.exr");
    CHECK(!st_image_write(bad, &img, 0, &err) && err.kind == ST_ERR_RUNTIME, "NaN via dispatch");
    CHECK(!st_test_exists(bad) && !tmp_left(bad), "no NaN file");
    scratch(bad, sizeof bad, "nan.png");
    CHECK(!st_image_write(bad, &img, 0, &err) && err.kind == ST_ERR_RUNTIME, "NaN png");
    CHECK(!st_test_exists(bad) && !tmp_left(bad), "no NaN png");
    CHECK(st_image_count_nonfinite(&img) == 2, "count %zu", st_image_count_nonfinite(&img));
    img.data[7] = img.data[20] = 1.0f;
    CHECK(st_image_count_nonfinite(&img) == 0, "count after fix");

    scratch(bad, sizeof bad, "out.tif");
    CHECK(!st_image_write(bad, &img, 0, &err), "tif refused");
    CHECK(err.kind == ST_ERR_INPUT && strstr(err.msg, ".tif") && strstr(err.msg, bad),
          "tif message: %s", err.msg);
    CHECK(!st_test_exists(bad), "no tif written");
    scratch(bad, sizeof bad, "noext");
    CHECK(!st_image_write(bad, &img, 0, &err) && err.kind == ST_ERR_INPUT, "no extension");

    // Extension match is case-insensitive.
    scratch(bad, sizeof bad, "UPPER.EXR");
    CHECK(st_image_write(bad, &img, 0, &err), "upper-case .EXR: %s", err.msg);
    CHECK(st_image_read_exr(bad, &back, &err) && back.data[35] == 8.75f, "read .EXR");
    st_image_free(&back);

    snprintf(bad, sizeof bad, "%s/no/such/dir/x.exr", ST_TEST_SCRATCH);
    CHECK(!st_image_write(bad, &img, 0, &err) && err.kind == ST_ERR_RUNTIME && strstr(err.msg, bad),
          "unwritable path: %s", err.msg);

    // Reading: missing file, not an EXR, no usable channels.
    snprintf(bad, sizeof bad, "%s/does-not-exist.exr", ST_TEST_SCRATCH);
    CHECK(!st_image_read_exr(bad, &back, &err) && err.kind == ST_ERR_INPUT &&
              strstr(err.msg, bad) && strstr(err.msg, "No such file"),
          "missing: %s", err.msg);
    scratch(bad, sizeof bad, "garbage.exr");
    FILE *f = fopen(bad, "wb");
    fputs("this is not an EXR file, just some text\n", f);
    fclose(f);
    CHECK(!st_image_read_exr(bad, &back, &err) && err.kind == ST_ERR_INPUT && strstr(err.msg, bad),
          "garbage: %s", err.msg);
    CHECK(back.data == NULL, "no image on failure");
    scratch(bad, sizeof bad, "xyz.exr");
    static const char *const xyz[] = {"X", "Y.nope", "Z"};
    CHECK(st_image_write_exr_named(bad, &img, xyz, &err), "%s", err.msg);
    CHECK(!st_image_read_exr(bad, &back, &err) && err.kind == ST_ERR_INPUT &&
              strstr(err.msg, "no R,G,B or Y") && strstr(err.msg, "Y.nope"),
          "no RGB: %s", err.msg);

    CHECK(!st_image_alloc(&back, 0, 5, 3, &err) && err.kind == ST_ERR_INPUT, "0 width");
    CHECK(!st_image_alloc(&back, 5, 5, 0, &err), "0 channels");
    st_image_free(&img);
}

int main(void) {
    roundtrip("rt_37x19.exr", 37, 19, 3);
    roundtrip("rt_1x1.exr", 1, 1, 3);
    roundtrip("rt_rgba.exr", 37, 19, 4);
    roundtrip("rt_y.exr", 5, 3, 1);
    roundtrip("rt_tall.exr", 3, 70, 3); // several 16-line ZIP chunks plus a partial one
    test_half();
    test_named();
    test_refusals();
    return st_test_summary("test_image_exr");
}
