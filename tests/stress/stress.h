// Shared pieces of the stress suite: scenes written to the test's scratch
// folder, `strahl render` / `strahl reference` runs that must either give a
// finite image or refuse with exit 2 (one message line naming the culprit, no
// output file), image statistics, the analytic direct light of a pixel, and
// a tiny binary glTF writer for meshes the JSON cannot describe.
#ifndef STRESS_H
#define STRESS_H
#include "st_test_render.h"
#include "st_test_support.h"
#include <stdint.h>
#include <time.h>

#define S_PI 3.14159265358979323846

static char stress_msg[1 << 15];

typedef struct stress_stats {
    size_t nonfinite, negative, lit; // lit: values > 0
    double min, max, mean;
} stress_stats;

static inline stress_stats stress_image_stats(const st_image *img) {
    stress_stats s = {0, 0, 0, INFINITY, -INFINITY, 0};
    size_t n = (size_t)img->width * img->height * img->channels;
    double sum = 0;
    for (size_t k = 0; k < n; k++) {
        float v = img->data[k];
        if (!isfinite(v)) {
            s.nonfinite++;
            continue;
        }
        s.negative += v<0, s.lit += v> 0;
        s.min = fmin(s.min, v), s.max = fmax(s.max, v), sum += v;
    }
    s.mean = n ? sum / (double)n : 0;
    return s;
}

static inline double stress_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static inline void stress_path(char *out, size_t n, const char *name, const char *ext) {
    snprintf(out, n, "%s/%s.%s", ST_TEST_SCRATCH, name, ext);
}

// Runs `strahl CMD SCRATCH/name.json -o SCRATCH/name.exr --filter point EXTRA`
// with the scene `json` (NULL: the file is already there), output captured in
// stress_msg. The point filter: the checks are against pixel-centre values,
// and one frame of a 4096 x 4096 image is the stress, not 64 of them.
static inline int stress_run(const char *cmd, const char *name, const char *json,
                             const char *extra) {
    char scene[512], out[512], line[8192];
    stress_path(scene, sizeof scene, name, "json");
    stress_path(out, sizeof out, name, "exr");
    if (json) st_test_write(scene, json);
    unlink(out);
    snprintf(line, sizeof line, "%s %s %s -o %s --filter point %s", ST_TEST_STRAHL, cmd, scene, out,
             extra ? extra : "");
    return st_test_capture(stress_msg, sizeof stress_msg, line);
}

// The command must succeed with every value finite; the image is returned in
// img (free it). Returns 0 when it did not (already counted as a failure).
static inline int stress_ok(const char *cmd, const char *name, const char *json, const char *extra,
                            st_image *img) {
    char out[512];
    stress_path(out, sizeof out, name, "exr");
    int rc = stress_run(cmd, name, json, extra);
    CHECK(rc == 0, "%s %s: exit code %d, want 0: %s", cmd, name, rc, stress_msg);
    if (rc != 0) return 0;
    st_image tmp = {0};
    if (!img) img = &tmp;
    if (!st_test_read(out, img)) {
        CHECK(0, "%s %s: output unreadable", cmd, name);
        return 0;
    }
    size_t bad = st_image_count_nonfinite(img);
    CHECK(bad == 0, "%s %s: %zu non-finite values", cmd, name, bad);
    st_image_free(&tmp);
    unlink(out);
    return bad == 0;
}

// The GL context of the renders made in this process (on first use).
static st_context *stress_ctx;

// `strahl render` as stress_ok checks it; without extra options the scene
// renders in this process instead (st_test_render_here, as `strahl render
// --filter point` does): these programs render many small scenes, and a
// process start-up per scene cost several times the render.
static inline int stress_render(const char *name, const char *json, const char *extra,
                                st_image *img) {
    if (extra) return stress_ok("render", name, json, extra, img);
    char scene[512];
    stress_path(scene, sizeof scene, name, "json");
    if (json) st_test_write(scene, json);
    if (!stress_ctx) stress_ctx = st_test_context();
    st_err err = {0};
    st_image tmp = {0};
    if (!img) img = &tmp;
    bool ok = st_test_render_here(scene, img, &err);
    CHECK(ok, "render %s: %s", name, err.msg);
    if (!ok) return 0;
    size_t bad = st_image_count_nonfinite(img);
    CHECK(bad == 0, "render %s: %zu non-finite values", name, bad);
    st_image_free(&tmp);
    return bad == 0;
}

// Counts lines of the captured message.
static inline int stress_msg_lines(void) {
    int lines = 0;
    for (const char *p = stress_msg; *p; p++)
        lines += *p == '\n';
    return lines;
}

// The command must refuse: exit 2, one message line containing `culprit`, no
// output file.
static inline void stress_refused(const char *cmd, const char *name, const char *json,
                                  const char *extra, const char *culprit) {
    char out[512];
    stress_path(out, sizeof out, name, "exr");
    int rc = stress_run(cmd, name, json, extra);
    CHECK(rc == 2, "%s %s: exit code %d, want 2: %s", cmd, name, rc, stress_msg);
    CHECK(strstr(stress_msg, culprit) != NULL, "%s %s: message names '%s': %s", cmd, name, culprit,
          stress_msg);
    CHECK(stress_msg_lines() == 1, "%s %s: one message line, got %d", cmd, name,
          stress_msg_lines());
    CHECK(!st_test_exists(out), "%s %s: no output file", cmd, name);
}

// Relative L1 difference sum |a - b| / sum |b| over all values.
static inline double stress_rel_l1(const st_image *a, const st_image *b) {
    if (a->width != b->width || a->height != b->height || a->channels != b->channels)
        return INFINITY;
    size_t n = (size_t)a->width * a->height * a->channels;
    double num = 0, den = 0;
    for (size_t k = 0; k < n; k++)
        num += fabs((double)a->data[k] - b->data[k]), den += fabs((double)b->data[k]);
    return den > 0 ? num / den : (num > 0 ? INFINITY : 0);
}

// Direct light (no occlusion) at the point pixel (i, j) sees on a plane with
// normal n through point q: rho/pi I cos / d^2 from each light, 0 behind the
// plane or when the plane is not hit. Writes the hit distance to *t.
static inline double stress_plane_direct(const st_test_cam *c, int i, int j, const double q[3],
                                         const double n[3], double rho, const double light[3],
                                         double I, double *t) {
    double d[3];
    st_test_ray(c, i, j, d);
    double dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
    double qn = (q[0] - c->pos[0]) * n[0] + (q[1] - c->pos[1]) * n[1] + (q[2] - c->pos[2]) * n[2];
    *t = dn != 0 ? qn / dn : -1;
    if (!(*t > 0) || dn >= 0) return 0; // missed, or seen from behind
    double l[3], d2 = 0, ln = 0;
    for (int k = 0; k < 3; k++)
        l[k] = light[k] - (c->pos[k] + *t * d[k]), d2 += l[k] * l[k], ln += l[k] * n[k];
    return ln <= 0 ? 0 : rho / S_PI * I * ln / (d2 * sqrt(d2));
}

// ---- module configurations --------------------------------------------------

// Every plugin with what it needs (toth: shadow_map and a medium; the god-ray
// post-processes: a medium), at cheap settings so a stress case costs a
// fraction of a second on llvmpipe. `direct` marks configurations whose image
// is the plain direct light (the analytic sanity numbers apply).
typedef struct stress_config {
    const char *name, *modules, *medium;
    int direct;
} stress_config;

#define STRESS_MEDIUM                                                                              \
    "{\"sigma_s\": [0.2, 0.2, 0.2], \"sigma_a\": [0.05, 0.05, 0.05], \"phase\": {\"hg\": 0.3}}"
#define STRESS_SHADOW "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 128}}"

static const stress_config stress_configs[] = {
    {"none", "[]", NULL, 1},
    {"shadow_map", "[" STRESS_SHADOW "]", NULL, 1},
    {"toth", "[" STRESS_SHADOW ", {\"name\": \"toth\", \"params\": {\"samples\": 16}}]",
     STRESS_MEDIUM, 0},
    {"mitchell", "[{\"name\": \"mitchell\", \"params\": {\"n\": 32}}]", STRESS_MEDIUM, 0},
    {"sousa", "[{\"name\": \"sousa\"}]", STRESS_MEDIUM, 0},
    {"atlas_gi",
     "[" STRESS_SHADOW ", {\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 64, \"mode\": "
     "\"gather\", \"visibility\": false, \"sampling\": \"uniform\", "
     "\"progressive\": false, \"samples\": 256}}]",
     NULL, 0},
    {"ssgi", "[{\"name\": \"ssgi\", \"params\": {\"samples\": 16}}]", NULL, 0},
};
#define STRESS_NUM_CONFIGS ((int)(sizeof stress_configs / sizeof stress_configs[0]))

// The scene's tail after "geometry": the medium (if any) and the modules.
static inline void stress_config_tail(char *out, size_t n, const stress_config *c) {
    snprintf(out, n, "%s%s%s \"modules\": %s}", c->medium ? " \"medium\": " : "",
             c->medium ? c->medium : "", c->medium ? "," : "", c->modules);
}

// ---- binary glTF --------------------------------------------------------------

static inline void stress_put32(unsigned char *p, uint32_t v) {
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

// Writes a .glb with one mesh of one indexed triangle primitive (nrm may be
// NULL: no NORMAL attribute) on one node; `node_extra` is spliced into the
// node object (e.g. ", \"scale\": [1, 0, 1]"). Returns 1 on success.
static inline int stress_write_glb(const char *path, const float *pos, const float *nrm,
                                   uint32_t nv, const uint32_t *idx, uint32_t ni,
                                   const char *node_extra) {
    size_t pb = (size_t)nv * 12, nb = nrm ? pb : 0, ib = (size_t)ni * 4, bl = pb + nb + ib;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++)
            lo[k] = fminf(lo[k], pos[3 * v + k]), hi[k] = fmaxf(hi[k], pos[3 * v + k]);
    char json[4096], nview[256] = "", nacc[256] = "", nattr[32] = "";
    if (nrm) {
        snprintf(nview, sizeof nview, ", {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}",
                 pb, nb);
        snprintf(
            nacc, sizeof nacc,
            ", {\"bufferView\": 2, \"componentType\": 5126, \"count\": %u, \"type\": \"VEC3\"}",
            nv);
        snprintf(nattr, sizeof nattr, ", \"NORMAL\": 2");
    }
    snprintf(
        json, sizeof json,
        "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],"
        " \"nodes\": [{\"mesh\": 0%s}],"
        " \"meshes\": [{\"name\": \"stress\", \"primitives\": [{\"attributes\": {\"POSITION\": "
        "0%s},"
        " \"indices\": 1}]}],"
        " \"buffers\": [{\"byteLength\": %zu}],"
        " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": %zu},"
        " {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}%s],"
        " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": %u, \"type\": "
        "\"VEC3\","
        " \"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]},"
        " {\"bufferView\": 1, \"componentType\": 5125, \"count\": %u, \"type\": \"SCALAR\"}%s]}",
        node_extra ? node_extra : "", nattr, bl, pb, pb + nb, ib, nview, nv, lo[0], lo[1], lo[2],
        hi[0], hi[1], hi[2], ni, nacc);
    size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3, bp = (bl + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jp + 8 + bp;
    unsigned char *buf = calloc(1, total);
    if (!buf) return 0;
    memcpy(buf, "glTF", 4);
    stress_put32(buf + 4, 2);
    stress_put32(buf + 8, (uint32_t)total);
    stress_put32(buf + 12, (uint32_t)jp);
    stress_put32(buf + 16, 0x4E4F534A); // JSON
    memcpy(buf + 20, json, jl);
    memset(buf + 20 + jl, ' ', jp - jl);
    unsigned char *b = buf + 20 + jp;
    stress_put32(b, (uint32_t)bp);
    stress_put32(b + 4, 0x004E4942); // BIN
    memcpy(b + 8, pos, pb);
    if (nrm) memcpy(b + 8 + pb, nrm, nb);
    memcpy(b + 8 + pb + nb, idx, ib);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(buf, 1, total, f) == total;
    if (f) ok &= fclose(f) == 0;
    free(buf);
    return ok;
}

#endif
