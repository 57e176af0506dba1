// Float images: allocation, EXR I/O through OpenEXRCore's C API, PNG output
// through stb_image_write. Every writer goes through a temporary file beside
// the target and a rename (st_outfile), so a failed write never leaves
// partial output; every reader through st_open_input.
#define _POSIX_C_SOURCE 200809L
#include "st_image.h"
#include "st_file.h"
#include <sys/stat.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

bool st_image_alloc(st_image *img, int width, int height, int channels, st_err *err) {
    *img = (st_image){0};
    if (width <= 0 || height <= 0 || channels <= 0 || channels > ST_IMAGE_MAX_CHANNELS)
        return st_fail(err, ST_ERR_INPUT, "invalid image size %dx%d with %d channels", width,
                       height, channels);
    size_t n = (size_t)width * (size_t)height;
    if (n > SIZE_MAX / sizeof(float) / (size_t)channels)
        return st_fail(err, ST_ERR_INPUT, "image %dx%d is too large", width, height);
    img->data = calloc(n * (size_t)channels, sizeof(float));
    if (!img->data)
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for a %dx%d image", width, height);
    img->width = width;
    img->height = height;
    img->channels = channels;
    return true;
}

void st_image_free(st_image *img) {
    if (!img) return;
    free(img->data);
    *img = (st_image){0};
}

size_t st_image_count_nonfinite(const st_image *img) {
    if (!img || !img->data) return 0;
    size_t n = (size_t)img->width * img->height * img->channels, bad = 0;
    for (size_t i = 0; i < n; i++)
        bad += !isfinite(img->data[i]);
    return bad;
}

double st_srgb_encode(double v) {
    if (!(v > 0.0)) return 0.0; // also maps NaN to 0
    if (v >= 1.0) return 1.0;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

// ---------------------------------------------------------------------------
// Atomic output helpers

static bool check_writable(const char *path, const st_image *img, st_err *err) {
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "empty output path");
    if (!img || !img->data || img->width <= 0 || img->height <= 0 || img->channels <= 0)
        return st_fail(err, ST_ERR_INPUT, "%s: no image to write", path);
    size_t bad = st_image_count_nonfinite(img);
    if (bad)
        return st_fail(err, ST_ERR_RUNTIME,
                       "%s: refusing to write an image with %zu non-finite (NaN/Inf) values", path,
                       bad);
    return true;
}

// ---------------------------------------------------------------------------
// EXR

// OpenEXRCore prints errors to stderr by default; keep the last message here
// instead so it ends up in st_err.
static _Thread_local char exr_msg[512];

static void exr_quiet(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
    (void)ctxt;
    snprintf(exr_msg, sizeof exr_msg, "%s", msg ? msg : exr_get_default_error_message(code));
}

static bool exr_fail(st_err *err, st_err_kind kind, const char *path, const char *what,
                     exr_result_t rc) {
    return st_fail(err, kind, "%s: %s: %s", path, what,
                   exr_msg[0] ? exr_msg : exr_get_default_error_message(rc));
}

static exr_context_initializer_t exr_init(void) {
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_quiet;
    return init;
}

// OpenEXRCore 3.1's ZIP compressor, when deflate does not shrink a chunk,
// falls back to "stored" but leaves other bytes than the raw chunk in the
// output; readers take a chunk whose size equals the raw size as raw, so it
// came back as garbage (noisy float data, e.g. jittered renders, hit this).
// Store such chunks raw ourselves.
static exr_result_t (*exr_default_compress)(exr_encode_pipeline_t *);
static exr_result_t exr_compress_or_store(exr_encode_pipeline_t *e) {
    exr_result_t rc = exr_default_compress(e);
    if (rc == EXR_ERR_SUCCESS && e->compressed_bytes >= e->packed_bytes) {
        memcpy(e->compressed_buffer, e->packed_buffer, e->packed_bytes);
        e->compressed_bytes = e->packed_bytes;
    }
    return rc;
}

static int64_t exr_pwrite(exr_const_context_t ctxt, void *user, const void *buf, uint64_t sz,
                          uint64_t off, exr_stream_error_func_ptr_t error_cb) {
    (void)ctxt;
    (void)error_cb;
    int fd = (int)(intptr_t)user;
    uint64_t put = 0;
    while (put < sz) {
        ssize_t r = pwrite(fd, (const char *)buf + put, sz - put, (off_t)(off + put));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return -1;
        put += (uint64_t)r;
    }
    return (int64_t)put;
}

// Defines the header of part 0 (a scanline image of FLOAT channels, ZIP,
// the metadata as attributes) and writes it; *what says which step failed.
static exr_result_t exr_header(exr_context_t ctx, const st_image *img, const char *const *names,
                               const st_exr_meta *meta, const char **what) {
    exr_result_t rc;
    int part = 0;
    *what = "cannot define header";
    if ((rc = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part))) return rc;
    if ((rc = exr_initialize_required_attr_simple(ctx, part, img->width, img->height,
                                                  EXR_COMPRESSION_ZIP)))
        return rc;
    for (int c = 0; c < img->channels; c++) {
        if (strlen(names[c]) > 31 && (rc = exr_set_longname_support(ctx, 1))) return rc;
        rc = exr_add_channel(ctx, part, names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1,
                             1);
        if (rc) {
            *what = "cannot add channel";
            return rc;
        }
    }
    *what = "cannot add attribute";
    if (meta && meta->spp > 0 && (rc = exr_attr_set_int(ctx, part, "spp", meta->spp))) return rc;
    if (meta && meta->seeds[0] &&
        (rc = exr_attr_set_string(ctx, part, "strahl.seeds", meta->seeds)))
        return rc;
    if (meta && meta->config[0] &&
        (rc = exr_attr_set_string(ctx, part, "strahl.config", meta->config)))
        return rc;
    if (meta && meta->filter[0] &&
        (rc = exr_attr_set_string(ctx, part, "strahl.filter", meta->filter)))
        return rc;
    *what = "cannot define header";
    return exr_write_header(ctx);
}

// Points the encoder's channels (sorted by name in the file) at their
// interleaved positions in row y of img.
static exr_result_t exr_bind_channels(exr_encode_pipeline_t *enc, const st_image *img,
                                      const char *const *names, int y) {
    const int nc = img->channels;
    for (int k = 0; k < enc->channel_count; k++) {
        exr_coding_channel_info_t *ch = &enc->channels[k];
        int src = -1;
        for (int c = 0; c < nc && src < 0; c++)
            if (!strcmp(ch->channel_name, names[c])) src = c;
        if (src < 0) return EXR_ERR_INVALID_ARGUMENT;
        ch->user_data_type = EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = 4;
        ch->user_pixel_stride = nc * 4;
        ch->user_line_stride = img->width * nc * 4;
        ch->encode_from_ptr = (const uint8_t *)(st_image_px(img, 0, y) + src);
    }
    return EXR_ERR_SUCCESS;
}

// Encodes and writes every scanline chunk of part 0.
static exr_result_t exr_pixels(exr_context_t ctx, const st_image *img, const char *const *names,
                               exr_encode_pipeline_t *enc, bool *enc_ready) {
    const int part = 0;
    exr_result_t rc;
    int32_t lines = 0;
    if ((rc = exr_get_scanlines_per_chunk(ctx, part, &lines))) return rc;
    for (int y = 0; y < img->height; y += lines) {
        exr_chunk_info_t ci;
        if ((rc = exr_write_scanline_chunk_info(ctx, part, y, &ci))) return rc;
        rc = *enc_ready ? exr_encoding_update(ctx, part, &ci, enc)
                        : exr_encoding_initialize(ctx, part, &ci, enc);
        if (rc || (rc = exr_bind_channels(enc, img, names, y))) return rc;
        if (!*enc_ready) {
            if ((rc = exr_encoding_choose_default_routines(ctx, part, enc))) return rc;
            exr_default_compress = enc->compress_fn;
            enc->compress_fn = exr_compress_or_store;
            *enc_ready = true;
        }
        if ((rc = exr_encoding_run(ctx, part, enc))) return rc;
    }
    return EXR_ERR_SUCCESS;
}

// Writes the whole image as FLOAT scanlines with ZIP compression to the
// descriptor fd (the temporary file of path).
static bool exr_write_file(int fd, const char *path, const st_image *img, const char *const *names,
                           const st_exr_meta *meta, st_err *err) {
    exr_msg[0] = 0;
    exr_context_initializer_t init = exr_init();
    init.user_data = (void *)(intptr_t)fd;
    init.write_fn = exr_pwrite;
    exr_context_t ctx = NULL;
    exr_result_t rc = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rc != EXR_ERR_SUCCESS) {
        if (ctx) exr_finish(&ctx);
        return exr_fail(err, ST_ERR_RUNTIME, path, "cannot create", rc);
    }
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool enc_ready = false;
    const char *what = "cannot define header";
    rc = exr_header(ctx, img, names, meta, &what);
    if (!rc) {
        what = "cannot write pixels";
        rc = exr_pixels(ctx, img, names, &enc, &enc_ready);
    }
    if (enc_ready || enc.channels) exr_encoding_destroy(ctx, &enc);
    exr_result_t frc = exr_finish(&ctx);
    if (rc) return exr_fail(err, ST_ERR_RUNTIME, path, what, rc);
    if (frc) return exr_fail(err, ST_ERR_RUNTIME, path, "cannot finish file", frc);
    return true;
}

bool st_image_write_exr_meta(const char *path, const st_image *img, const char *const *names,
                             const st_exr_meta *meta, st_err *err) {
    if (!check_writable(path, img, err)) return false;
    for (int c = 0; c < img->channels; c++) {
        if (!names || !names[c] || !names[c][0])
            return st_fail(err, ST_ERR_INPUT, "%s: channel %d has no name", path, c);
        for (int d = 0; d < c; d++)
            if (!strcmp(names[c], names[d]))
                return st_fail(err, ST_ERR_INPUT, "%s: channel name '%s' given twice", path,
                               names[c]);
    }
    if ((int64_t)img->width * img->channels * 4 > INT32_MAX) // the coder's line stride
        return st_fail(err, ST_ERR_INPUT, "%s: image too wide for EXR", path);
    st_outfile o;
    if (!st_out_begin(&o, path, err)) return false;
    if (!exr_write_file(o.fd, path, img, names, meta, err)) {
        st_out_abort(&o);
        return false;
    }
    return st_out_commit(&o, err);
}

bool st_image_write_exr_named(const char *path, const st_image *img, const char *const *names,
                              st_err *err) {
    return st_image_write_exr_meta(path, img, names, NULL, err);
}

bool st_image_write_exr(const char *path, const st_image *img, st_err *err) {
    static const char *const rgba[] = {"R", "G", "B", "A"}, *const y[] = {"Y"};
    if (img && (img->channels == 3 || img->channels == 4))
        return st_image_write_exr_named(path, img, rgba, err);
    if (img && img->channels == 1) return st_image_write_exr_named(path, img, y, err);
    return st_fail(err, ST_ERR_INPUT,
                   "%s: an image with %d channels needs channel names (st_image_write_exr_named)",
                   path ? path : "", img ? img->channels : 0);
}

// Decodes the channels src[k] (indices into the part's channel list) into
// channel k of out, chunk by chunk. Handles scanline and tiled (level 0) parts.
// Each chunk is decoded into planar float scratch and interleaved here:
// OpenEXRCore 3.1's specialised interleaved HALF->FLOAT unpacker for four
// channels swaps them (A,B,G,R land as R,G,B,A), the planar path is right.
static bool exr_decode(exr_context_t ctx, const char *path, exr_storage_t storage,
                       exr_attr_box2i_t dw, const int *src, const exr_attr_chlist_t *chl,
                       st_image *out, st_err *err) {
    const int w = out->width, h = out->height, nc = out->channels;
    int32_t tw = w, th = h, nx = 1, ny = 1, lines = 1;
    exr_result_t rc;
    if (storage == EXR_STORAGE_TILED) {
        if ((rc = exr_get_tile_sizes(ctx, 0, 0, 0, &tw, &th)))
            return exr_fail(err, ST_ERR_INPUT, path, "bad tile description", rc);
        if (tw <= 0 || th <= 0) return st_fail(err, ST_ERR_INPUT, "%s: bad tile size", path);
        nx = (w + tw - 1) / tw;
        ny = (h + th - 1) / th;
    } else {
        if ((rc = exr_get_scanlines_per_chunk(ctx, 0, &lines)) || lines <= 0)
            return exr_fail(err, ST_ERR_INPUT, path, "bad scanline layout", rc);
        tw = w;
        th = lines;
        ny = (h + lines - 1) / lines;
    }
    float *plane = malloc((size_t)tw * (size_t)th * (size_t)nc * sizeof(float));
    if (!plane) return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    bool ready = false, ok = false;
    for (int ty = 0; ty < ny; ty++) {
        for (int tx = 0; tx < nx; tx++) {
            exr_chunk_info_t ci;
            int x0, y0; // chunk origin relative to the data window
            if (storage == EXR_STORAGE_TILED) {
                rc = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci);
                x0 = tx * tw;
                y0 = ty * th;
            } else {
                rc = exr_read_scanline_chunk_info(ctx, 0, dw.min.y + ty * lines, &ci);
                x0 = 0;
                y0 = ci.start_y - dw.min.y;
            }
            if (rc) goto done;
            const int cw = ci.width, ch = ci.height;
            if (x0 < 0 || y0 < 0 || cw <= 0 || ch <= 0 || cw > tw || ch > th || x0 + cw > w ||
                y0 + ch > h) {
                rc = EXR_ERR_BAD_CHUNK_LEADER;
                goto done;
            }
            rc = ready ? exr_decoding_update(ctx, 0, &ci, &dec)
                       : exr_decoding_initialize(ctx, 0, &ci, &dec);
            if (rc) goto done;
            for (int k = 0; k < dec.channel_count; k++) {
                exr_coding_channel_info_t *info = &dec.channels[k];
                info->decode_to_ptr = NULL; // channels not asked for are skipped
                for (int c = 0; c < nc; c++) {
                    if (strcmp(info->channel_name, chl->entries[src[c]].name.str)) continue;
                    info->user_data_type = EXR_PIXEL_FLOAT; // HALF is converted
                    info->user_bytes_per_element = 4;
                    info->user_pixel_stride = 4;
                    info->user_line_stride = cw * 4;
                    info->decode_to_ptr = (uint8_t *)(plane + (size_t)c * cw * ch);
                }
            }
            if (!ready) {
                if ((rc = exr_decoding_choose_default_routines(ctx, 0, &dec))) goto done;
                ready = true;
            }
            if ((rc = exr_decoding_run(ctx, 0, &dec))) goto done;
            for (int c = 0; c < nc; c++) {
                const float *p = plane + (size_t)c * cw * ch;
                for (int j = 0; j < ch; j++)
                    for (int i = 0; i < cw; i++)
                        st_image_px(out, x0 + i, y0 + j)[c] = p[(size_t)j * cw + i];
            }
        }
    }
    ok = true;
done:
    if (ready || dec.channels) exr_decoding_destroy(ctx, &dec);
    free(plane);
    return ok ? true : exr_fail(err, ST_ERR_INPUT, path, "cannot decode pixels", rc);
}

// Reading goes through a descriptor from st_open_input (a regular file
// within ST_CAP_EXR, never a FIFO or device), read with pread.
static int64_t exr_pread(exr_const_context_t ctxt, void *user, void *buf, uint64_t sz, uint64_t off,
                         exr_stream_error_func_ptr_t error_cb) {
    (void)ctxt;
    (void)error_cb;
    int fd = (int)(intptr_t)user;
    uint64_t got = 0;
    while (got < sz) {
        ssize_t r = pread(fd, (char *)buf + got, sz - got, (off_t)(off + got));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return -1;
        if (r == 0) break;
        got += (uint64_t)r;
    }
    return (int64_t)got;
}

static int64_t exr_fsize(exr_const_context_t ctxt, void *user) {
    (void)ctxt;
    struct stat st;
    return fstat((int)(intptr_t)user, &st) == 0 ? (int64_t)st.st_size : -1;
}

// Opens path for reading and checks it is a flat image whose first part we
// can decode; *fd stays open until exr_done.
static bool exr_open(const char *path, exr_context_t *ctx, int *fd, st_err *err) {
    *ctx = NULL;
    *fd = st_open_input(path, ST_CAP_EXR, "EXR image", NULL, err);
    if (*fd < 0) return false;
    exr_msg[0] = 0;
    exr_context_initializer_t init = exr_init();
    init.flags = EXR_CONTEXT_FLAG_SILENT_HEADER_PARSE;
    init.user_data = (void *)(intptr_t)*fd;
    init.read_fn = exr_pread;
    init.size_fn = exr_fsize;
    exr_result_t rc = exr_start_read(ctx, path, &init);
    if (rc != EXR_ERR_SUCCESS) {
        if (*ctx) exr_finish(ctx);
        close(*fd);
        return exr_fail(err, ST_ERR_INPUT, path, "not a readable EXR file", rc);
    }
    return true;
}

static void exr_done(exr_context_t *ctx, int fd) {
    exr_finish(ctx);
    close(fd);
}

static bool exr_read_named(exr_context_t ctx, const char *path, const char *const *names, int count,
                           st_image *out, st_err *err) {
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    exr_result_t rc;
    if ((rc = exr_get_storage(ctx, 0, &storage)))
        return exr_fail(err, ST_ERR_INPUT, path, "no image part", rc);
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return st_fail(err, ST_ERR_INPUT, "%s: deep EXR images are not supported", path);
    if ((rc = exr_get_data_window(ctx, 0, &dw)) || (rc = exr_get_channels(ctx, 0, &chl)))
        return exr_fail(err, ST_ERR_INPUT, path, "bad header", rc);
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > INT_MAX || h > INT_MAX)
        return st_fail(err, ST_ERR_INPUT, "%s: bad data window", path);
    // A header may claim any size; the pixels must come from the file. No
    // EXR compression (deflate at best ~1000:1) packs more than 1100 bytes of
    // samples into a byte of file, so a claim beyond that is refused before
    // allocating.
    void *user = NULL;
    int64_t fsize = exr_get_user_data(ctx, &user) == EXR_ERR_SUCCESS ? exr_fsize(ctx, user) : -1;
    uint64_t bpp = 0; // bytes per pixel of all the file's channels
    for (int k = 0; k < chl->num_channels; k++)
        bpp += chl->entries[k].pixel_type == EXR_PIXEL_HALF ? 2 : 4;
    if (fsize >= 0 && bpp && (uint64_t)w * (uint64_t)h > (1100 * (uint64_t)fsize + 65536) / bpp)
        return st_fail(
            err, ST_ERR_INPUT,
            "%s: the header claims %lldx%lld pixels, more than a %lld-byte file can hold", path,
            (long long)w, (long long)h, (long long)fsize);
    int src[ST_IMAGE_MAX_CHANNELS];
    if (count <= 0 || count > ST_IMAGE_MAX_CHANNELS)
        return st_fail(err, ST_ERR_INPUT, "%s: cannot read %d channels", path, count);
    for (int c = 0; c < count; c++) {
        src[c] = -1;
        if (!names || !names[c])
            return st_fail(err, ST_ERR_INPUT, "%s: channel %d has no name", path, c);
        for (int k = 0; k < chl->num_channels; k++)
            if (!strcmp(chl->entries[k].name.str, names[c])) src[c] = k;
        if (src[c] < 0) return st_fail(err, ST_ERR_INPUT, "%s: no channel '%s'", path, names[c]);
        for (int d = 0; d < c; d++)
            if (src[d] == src[c])
                return st_fail(err, ST_ERR_INPUT, "%s: channel '%s' asked for twice", path,
                               names[c]);
        const exr_attr_chlist_entry_t *e = &chl->entries[src[c]];
        if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT)
            return st_fail(err, ST_ERR_INPUT, "%s: channel '%s' is not HALF or FLOAT", path,
                           names[c]);
        if (e->x_sampling != 1 || e->y_sampling != 1)
            return st_fail(err, ST_ERR_INPUT, "%s: channel '%s' is subsampled", path, names[c]);
    }
    if (!st_image_alloc(out, (int)w, (int)h, count, err)) {
        st_err_prefix(err, "%s: ", path);
        return false;
    }
    if (!exr_decode(ctx, path, storage, dw, src, chl, out, err)) {
        st_image_free(out);
        return false;
    }
    return true;
}

bool st_image_read_exr_channels(const char *path, const char *const *names, int count,
                                st_image *out, st_err *err) {
    *out = (st_image){0};
    exr_context_t ctx;
    int fd;
    if (!exr_open(path, &ctx, &fd, err)) return false;
    bool ok = exr_read_named(ctx, path, names, count, out, err);
    exr_done(&ctx, fd);
    return ok;
}

static bool has_channel(const exr_attr_chlist_t *chl, const char *name) {
    for (int k = 0; k < chl->num_channels; k++)
        if (!strcmp(chl->entries[k].name.str, name)) return true;
    return false;
}

bool st_image_read_exr(const char *path, st_image *out, st_err *err) {
    static const char *const rgba[] = {"R", "G", "B", "A"}, *const y[] = {"Y"};
    *out = (st_image){0};
    exr_context_t ctx;
    int fd;
    if (!exr_open(path, &ctx, &fd, err)) return false;
    const exr_attr_chlist_t *chl = NULL;
    bool ok = false;
    exr_result_t rc = exr_get_channels(ctx, 0, &chl);
    if (rc || !chl) {
        exr_fail(err, ST_ERR_INPUT, path, "bad channel list", rc);
    } else if (has_channel(chl, "R") && has_channel(chl, "G") && has_channel(chl, "B")) {
        ok = exr_read_named(ctx, path, rgba, has_channel(chl, "A") ? 4 : 3, out, err);
    } else if (has_channel(chl, "Y")) {
        ok = exr_read_named(ctx, path, y, 1, out, err);
    } else {
        char list[512] = "";
        size_t len = 0;
        for (int k = 0; k < chl->num_channels && len < sizeof list; k++)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k ? ", " : "",
                                    chl->entries[k].name.str);
        st_fail(err, ST_ERR_INPUT, "%s: no R,G,B or Y channels (has: %s)", path,
                chl->num_channels ? list : "none");
    }
    exr_done(&ctx, fd);
    return ok;
}

bool st_image_read_exr_meta(const char *path, st_exr_meta *meta, st_err *err) {
    *meta = (st_exr_meta){0};
    exr_context_t ctx;
    int fd;
    if (!exr_open(path, &ctx, &fd, err)) return false;
    int32_t spp = 0, len = 0;
    const char *seeds = NULL;
    if (exr_attr_get_int(ctx, 0, "spp", &spp) == EXR_ERR_SUCCESS)
        meta->spp = spp, meta->has_spp = true;
    if (exr_attr_get_string(ctx, 0, "strahl.seeds", &len, &seeds) == EXR_ERR_SUCCESS && seeds &&
        len > 0)
        snprintf(meta->seeds, sizeof meta->seeds, "%.*s", (int)len, seeds);
    const char *config = NULL;
    if (exr_attr_get_string(ctx, 0, "strahl.config", &len, &config) == EXR_ERR_SUCCESS && config &&
        len > 0)
        snprintf(meta->config, sizeof meta->config, "%.*s", (int)len, config);
    const char *filter = NULL;
    if (exr_attr_get_string(ctx, 0, "strahl.filter", &len, &filter) == EXR_ERR_SUCCESS && filter &&
        len > 0)
        snprintf(meta->filter, sizeof meta->filter, "%.*s", (int)len, filter);
    exr_done(&ctx, fd);
    return true;
}

bool st_image_read_exr_stderr(const char *path, st_image *out, st_err *err) {
    static const char *const names[] = {"stderr.R", "stderr.G", "stderr.B"};
    *out = (st_image){0};
    exr_context_t ctx;
    int fd;
    if (!exr_open(path, &ctx, &fd, err)) return false;
    const exr_attr_chlist_t *chl = NULL;
    bool ok = true;
    exr_result_t rc = exr_get_channels(ctx, 0, &chl);
    if (rc || !chl)
        ok = exr_fail(err, ST_ERR_INPUT, path, "bad channel list", rc);
    else if (has_channel(chl, names[0]) && has_channel(chl, names[1]) && has_channel(chl, names[2]))
        ok = exr_read_named(ctx, path, names, 3, out, err);
    exr_done(&ctx, fd);
    return ok;
}

// ---------------------------------------------------------------------------
// PNG

typedef struct {
    FILE *f;
    bool bad;
} png_sink;

static void png_put(void *ctx, void *data, int size) {
    png_sink *s = ctx;
    if (!s->bad && fwrite(data, 1, (size_t)size, s->f) != (size_t)size) s->bad = true;
}

bool st_png_write8(const char *path, const uint8_t *px, int width, int height, int comp,
                   st_err *err) {
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "empty output path");
    if (!px || width <= 0 || height <= 0 || comp < 1 || comp > 4)
        return st_fail(err, ST_ERR_INPUT, "%s: no image to write", path);
    if ((size_t)width * comp > INT_MAX)
        return st_fail(err, ST_ERR_INPUT, "%s: image too wide for PNG", path);
    st_outfile o;
    if (!st_out_begin(&o, path, err)) return false;
    png_sink s = {st_out_stream(&o, err), false};
    if (!s.f) {
        st_out_abort(&o);
        return false;
    }
    int ok = stbi_write_png_to_func(png_put, &s, width, height, comp, px, width * comp);
    if (!ok || s.bad) {
        st_out_abort(&o);
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot write PNG%s", path,
                       ok ? " (I/O error)" : " (encoder failed)");
    }
    return st_out_commit(&o, err);
}

// CRC-32 of ISO 3309 (the PNG chunk checksum) over a chunk's type and data.
static uint32_t png_crc(const uint8_t *p, size_t n) {
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}

static bool png_text_ok(const char *key, const char *val) {
    size_t kl = strlen(key);
    if (kl < 1 || kl > 79 || key[0] == ' ' || key[kl - 1] == ' ') return false;
    for (const char *s = key; *s; s++)
        if ((unsigned char)*s < 0x20 || *s == 0x7f) return false;
    for (const char *s = val; *s; s++)
        if ((unsigned char)*s < 0x20 || *s == 0x7f) return false;
    return true;
}

static void put_be32(FILE *f, uint32_t v) {
    const uint8_t b[4] = {(uint8_t)(v >> 24), (uint8_t)(v >> 16), (uint8_t)(v >> 8), (uint8_t)v};
    fwrite(b, 1, 4, f);
}

// One tEXt chunk: length, "tEXt", key NUL value, CRC.
static bool png_text_chunk(FILE *f, const char *key, const char *val) {
    size_t kl = strlen(key), vl = strlen(val), n = 4 + kl + 1 + vl;
    uint8_t *c = malloc(n);
    if (!c) return false;
    memcpy(c, "tEXt", 4);
    memcpy(c + 4, key, kl + 1);
    memcpy(c + 5 + kl, val, vl);
    put_be32(f, (uint32_t)(n - 4));
    fwrite(c, 1, n, f);
    put_be32(f, png_crc(c, n));
    free(c);
    return true;
}

bool st_png_write8_text(const char *path, const uint8_t *px, int width, int height, int comp,
                        const char *const *text, st_err *err) {
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "empty output path");
    if (!px || width <= 0 || height <= 0 || comp < 1 || comp > 4)
        return st_fail(err, ST_ERR_INPUT, "%s: no image to write", path);
    if ((size_t)width * comp > INT_MAX)
        return st_fail(err, ST_ERR_INPUT, "%s: image too wide for PNG", path);
    for (int i = 0; text && text[i]; i += 2)
        if (!text[i + 1] || !png_text_ok(text[i], text[i + 1]))
            return st_fail(err, ST_ERR_INPUT, "%s: bad PNG text key or value '%.80s'", path,
                           text[i]);
    int len = 0;
    uint8_t *png = stbi_write_png_to_mem(px, width * comp, width, height, comp, &len);
    // 8 bytes of signature and the 25 of IHDR come first; the text follows them.
    const int head = 33;
    if (!png || len < head) {
        free(png);
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot write PNG (encoder failed)", path);
    }
    st_outfile o;
    FILE *f = st_out_begin(&o, path, err) ? st_out_stream(&o, err) : NULL;
    bool ok = f != NULL && fwrite(png, 1, head, f) == (size_t)head;
    for (int i = 0; ok && text && text[i]; i += 2)
        ok = png_text_chunk(f, text[i], text[i + 1]);
    ok = ok && fwrite(png + head, 1, (size_t)(len - head), f) == (size_t)(len - head);
    free(png);
    if (!ok) {
        st_out_abort(&o);
        return f ? st_fail(err, ST_ERR_RUNTIME, "%s: cannot write PNG (I/O error)", path) : false;
    }
    return st_out_commit(&o, err);
}

static uint8_t to8(double v) { // [0,1] -> 0..255, rounded
    return (uint8_t)floor(v * 255.0 + 0.5);
}

bool st_image_write_png(const char *path, const st_image *img, float exposure, st_err *err) {
    if (!check_writable(path, img, err)) return false;
    if (!isfinite(exposure))
        return st_fail(err, ST_ERR_INPUT, "%s: exposure %g is not finite", path, exposure);
    // 4 channels: RGBA; 3 or more: the first three as RGB; else grey.
    const int nc = img->channels, comp = nc == 4 ? 4 : nc >= 3 ? 3 : 1;
    const double scale = exp2((double)exposure);
    size_t n = (size_t)img->width * img->height;
    uint8_t *px = malloc(n * comp);
    if (!px) return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    for (size_t i = 0; i < n; i++) {
        const float *p = img->data + i * nc;
        for (int c = 0; c < comp; c++) {
            double v = p[c];
            // Alpha is coverage, not radiance: clamp only.
            px[i * comp + c] =
                c == 3 ? to8(fmin(fmax(v, 0.0), 1.0)) : to8(st_srgb_encode(v * scale));
        }
    }
    bool ok = st_png_write8(path, px, img->width, img->height, comp, err);
    free(px);
    return ok;
}

bool st_image_write(const char *path, const st_image *img, float exposure, st_err *err) {
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "empty output path");
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (dot && (!slash || dot > slash)) {
        if (!strcasecmp(dot, ".exr")) return st_image_write_exr(path, img, err);
        if (!strcasecmp(dot, ".png")) return st_image_write_png(path, img, exposure, err);
        return st_fail(err, ST_ERR_INPUT, "%s: unknown image extension '%s' (use .exr or .png)",
                       path, dot);
    }
    return st_fail(err, ST_ERR_INPUT, "%s: no image extension (use .exr or .png)", path);
}
