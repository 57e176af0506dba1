// The VDB helper's reply, read and checked in strahl (st_vdb_proto.h): the
// helper runs OpenVDB on a hostile file and may be compromised, so nothing
// it sends is trusted. The size is bounded by the voxel cap before anything
// is allocated, the reply must end exactly where its head says, and the
// block and map are checked as a file's would be before they are placed.
#define _GNU_SOURCE
#include "st_vdb_proto.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

// Reads up to n bytes, stopping early only at end of file; false when the
// deadline (CLOCK_MONOTONIC ms, 0: none) passes or read fails.
static bool read_some(int fd, void *buf, size_t n, uint64_t deadline, size_t *got,
                      bool *timed_out) {
    *got = 0;
    while (*got < n) {
        if (deadline) {
            const uint64_t now = (uint64_t)st_now_ms();
            if (now >= deadline) return *timed_out = true, false;
            struct pollfd p = {fd, POLLIN, 0};
            const uint64_t left = deadline - now;
            const int r = poll(&p, 1, left > INT_MAX ? INT_MAX : (int)left);
            if (r < 0 && errno != EINTR) return false;
            if (r <= 0) continue;
        }
        const ssize_t r = read(fd, (char *)buf + *got, n - *got);
        if (r < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (r < 0) return false;
        if (r == 0) break;
        *got += (size_t)r;
    }
    return true;
}

static bool malformed(st_err *err, const char *path, const char *what) {
    return st_fail(err, ST_ERR_INPUT,
                   "%s: the VDB reader " ST_VDB_READER_NAME
                   " sent a malformed reply (%s): a corrupt or hostile file",
                   path, what);
}

// Exactly n bytes then end of file.
static bool read_exact_end(int fd, void *buf, size_t n, const char *path, uint64_t deadline,
                           bool *timed_out, st_err *err) {
    size_t got;
    char extra;
    if (!read_some(fd, buf, n, deadline, &got, timed_out))
        return *timed_out ? false : malformed(err, path, "read error");
    if (got < n) return malformed(err, path, "shorter than its head says");
    if (!read_some(fd, &extra, 1, deadline, &got, timed_out))
        return *timed_out ? false : malformed(err, path, "read error");
    return got == 0 || malformed(err, path, "longer than its head says");
}

// The helper's own message (status 1: bad input, 2: runtime), escaped.
static bool reply_message(int fd, const st_vdb_head *h, const char *path, uint64_t deadline,
                          bool *timed_out, st_err *err) {
    if (h->msg_len == 0 || h->msg_len > ST_VDB_MSG_MAX)
        return malformed(err, path, "message length out of range");
    char msg[ST_VDB_MSG_MAX], out[sizeof((st_err *)0)->msg];
    if (!read_exact_end(fd, msg, h->msg_len, path, deadline, timed_out, err)) return false;
    size_t k = 0;
    for (uint32_t i = 0; i < h->msg_len && k + 5 < sizeof out; i++) {
        const unsigned char c = (unsigned char)msg[i];
        if (c < 0x20 || c == 0x7f)
            k += (size_t)snprintf(out + k, sizeof out - k, "\\x%02x", c);
        else
            out[k++] = (char)c;
    }
    out[k] = 0;
    return st_fail(err, h->status == 2 ? ST_ERR_RUNTIME : ST_ERR_INPUT, "%s", out);
}

bool st_vdb_read_reply(int fd, const char *path, uint64_t max_voxels, uint64_t deadline_ms,
                       st_vdb_raw *out, bool *timed_out, st_err *err) {
    memset(out, 0, sizeof *out);
    *timed_out = false;
    st_vdb_head h;
    size_t got;
    if (!read_some(fd, &h, sizeof h, deadline_ms, &got, timed_out))
        return *timed_out ? false : malformed(err, path, "read error");
    if (got < sizeof h) return malformed(err, path, "no complete head");
    if (memcmp(h.magic, ST_VDB_MAGIC, sizeof h.magic) != 0)
        return malformed(err, path, "bad magic");
    if (h.status == 1 || h.status == 2)
        return reply_message(fd, &h, path, deadline_ms, timed_out, err);
    if (h.status != 0 || h.msg_len != 0) return malformed(err, path, "bad status");
    uint64_t total = 1;
    for (int k = 0; k < 3; k++) {
        if (h.n[k] < 3 || (uint64_t)h.n[k] > max_voxels || h.lo[k] > INT_MAX - h.n[k])
            return malformed(err, path, "block size out of range");
        total *= (uint64_t)h.n[k];
        if (total > max_voxels) return malformed(err, path, "block above the voxel cap");
    }
    float *v = malloc(total * sizeof *v);
    if (!v) return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    if (!read_exact_end(fd, v, total * sizeof *v, path, deadline_ms, timed_out, err)) {
        free(v);
        return false;
    }
    memcpy(out->n, h.n, sizeof out->n);
    memcpy(out->lo, h.lo, sizeof out->lo);
    memcpy(out->map, h.map, sizeof out->map);
    out->values = v;
    return true;
}

// Inverts the 3x4 affine map m (row major, world = A p + b); false if singular.
static bool invert_affine(const double m[12], double out[12]) {
    const double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9],
                 i = m[10];
    const double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    const double det = a * A + b * B + c * C;
    double scale = 0;
    static const int lin[9] = {0, 1, 2, 4, 5, 6, 8, 9, 10};
    for (int k = 0; k < 9; k++)
        scale = fmax(scale, fabs(m[lin[k]]));
    if (!isfinite(det) || !(fabs(det) > 1e-12 * scale * scale * scale)) return false;
    const double inv[9] = {A / det, -(b * i - c * h) / det, (b * f - c * e) / det,
                           B / det, (a * i - c * g) / det,  -(a * f - c * d) / det,
                           C / det, -(a * h - b * g) / det, (a * e - b * d) / det};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            out[4 * r + k] = inv[3 * r + k];
        out[4 * r + 3] = -(inv[3 * r] * m[3] + inv[3 * r + 1] * m[7] + inv[3 * r + 2] * m[11]);
    }
    for (int k = 0; k < 12; k++)
        if (!isfinite(out[k])) return false;
    return true;
}

// World bounds of the block: the images of its eight corners.
static void block_bounds(st_density_grid *g) {
    for (int k = 0; k < 3; k++)
        g->bmin[k] = INFINITY, g->bmax[k] = -INFINITY;
    for (int c = 0; c < 8; c++) {
        const double p[3] = {(double)g->lo[0] + ((c & 1) ? g->n[0] - 1 : 0),
                             (double)g->lo[1] + ((c & 2) ? g->n[1] - 1 : 0),
                             (double)g->lo[2] + ((c & 4) ? g->n[2] - 1 : 0)};
        for (int r = 0; r < 3; r++) {
            const double w = g->to_world[4 * r] * p[0] + g->to_world[4 * r + 1] * p[1] +
                             g->to_world[4 * r + 2] * p[2] + g->to_world[4 * r + 3];
            g->bmin[r] = fmin(g->bmin[r], w);
            g->bmax[r] = fmax(g->bmax[r], w);
        }
    }
}

bool st_vdb_place(st_vdb_raw *raw, const char *path, const char *grid, uint64_t max_voxels,
                  const double translate[3], const double scale[3], st_density_grid *out,
                  st_err *err) {
    st_density_grid g;
    memset(&g, 0, sizeof g);
    uint64_t total = 1;
    bool ok = raw->values != NULL;
    for (int k = 0; k < 3 && ok; k++) {
        ok = raw->n[k] >= 3 && (uint64_t)raw->n[k] <= max_voxels &&
             raw->lo[k] <= INT_MAX - raw->n[k];
        total *= ok ? (uint64_t)raw->n[k] : 1;
        ok = ok && total <= max_voxels;
    }
    if (!ok) {
        free(raw->values), raw->values = NULL;
        return malformed(err, path, "block size out of range");
    }
    // The grid's map, then the scene's scale and translation.
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            g.to_world[4 * r + k] = scale[r] * raw->map[4 * r + k];
        g.to_world[4 * r + 3] = scale[r] * raw->map[4 * r + 3] + translate[r];
    }
    if (!invert_affine(g.to_world, g.to_index)) {
        free(raw->values), raw->values = NULL;
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s': its index-to-world map (with the scene's transform) is "
                       "singular or not finite",
                       path, grid);
    }
    double vmax = 0;
    for (uint64_t i = 0; i < total; i++) {
        const float v = raw->values[i];
        if (!(v >= 0.0f && v <= 3.4028234e38f)) { // also NaN
            free(raw->values), raw->values = NULL;
            return malformed(err, path, "a voxel value is not a finite value >= 0");
        }
        vmax = fmax(vmax, (double)v);
    }
    memcpy(g.n, raw->n, sizeof g.n);
    memcpy(g.lo, raw->lo, sizeof g.lo);
    g.values = raw->values;
    raw->values = NULL;
    g.max_value = vmax;
    block_bounds(&g);
    *out = g;
    return true;
}

void st_density_grid_free(st_density_grid *g) {
    if (!g) return;
    free(g->values);
    memset(g, 0, sizeof *g);
}
