// Shared by the mitchell and sousa tests: plain C implementations of both
// radial blurs (the shaders' loops, tap for tap, with GL's bilinear filtering
// and a zero border), texture upload/readback in GL orientation (row 0 at the
// bottom), and helpers that render a scene in-process and read pass stats.
#ifndef GODRAY_TEST_H
#define GODRAY_TEST_H
#include "st_test_render.h"
#include "st_world.h"
#include "st_godray.h"
#include "st_test_support.h"
#include <cjson/cJSON.h>

// ---- images in GL orientation: w x h texels of nc floats, row 0 bottom ----

typedef struct {
    int w, h, nc;
    float *px;
} gimg;

static inline gimg gimg_new(int w, int h, int nc) {
    gimg g = {w, h, nc, calloc((size_t)w * h * nc, sizeof(float))};
    if (!g.px) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    return g;
}
static inline float *gimg_at(const gimg *g, int x, int y) {
    return g->px + ((size_t)y * g->w + x) * g->nc;
}

// GL_LINEAR with GL_CLAMP_TO_BORDER, border 0 (GL 4.5 spec 8.14.2).
static inline void ref_bilinear(const gimg *g, float u, float v, float *out) {
    float x = u * g->w - 0.5f, y = v * g->h - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float a = x - fx, b = y - fy;
    for (int c = 0; c < g->nc; c++)
        out[c] = 0;
    if (!(fabsf(fx) < 1e8f && fabsf(fy) < 1e8f)) return; // far outside: all border
    int i = (int)fx, j = (int)fy;
    const float wts[4] = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
    const int xs[4] = {i, i + 1, i, i + 1}, ys[4] = {j, j, j + 1, j + 1};
    for (int t = 0; t < 4; t++) {
        if (xs[t] < 0 || ys[t] < 0 || xs[t] >= g->w || ys[t] >= g->h) continue;
        const float *p = gimg_at(g, xs[t], ys[t]);
        for (int c = 0; c < g->nc; c++)
            out[c] += wts[t] * p[c];
    }
}

typedef struct {
    float light[2];
    int n;
    float density, decay, weight, exposure, fade;
} mitchell_args;

// thesis listing A.4 / shaders/mitchell/blur.frag: out = hdr + fade exposure sum.
static inline void ref_mitchell(const gimg *occ, const gimg *hdr, const mitchell_args *a,
                                gimg *out) {
    for (int y = 0; y < out->h; y++)
        for (int x = 0; x < out->w; x++) {
            float uv[2] = {(x + 0.5f) / out->w, (y + 0.5f) / out->h};
            float d[2] = {(uv[0] - a->light[0]) / ((float)a->n * a->density),
                          (uv[1] - a->light[1]) / ((float)a->n * a->density)};
            float sum[4], t[4], p[2] = {uv[0], uv[1]}, decay_i = 1;
            ref_bilinear(occ, uv[0], uv[1], sum);
            for (int i = 0; i < a->n; i++) {
                p[0] -= d[0], p[1] -= d[1];
                ref_bilinear(occ, p[0], p[1], t);
                for (int c = 0; c < 3; c++)
                    sum[c] += t[c] * (decay_i * a->weight);
                decay_i *= a->decay;
            }
            float *o = gimg_at(out, x, y);
            const float *hp = gimg_at(hdr, x, y);
            for (int c = 0; c < 3; c++) {
                float s = fminf(sum[c], 1e30f);
                o[c] = fminf(hp[c] + s * (a->exposure * a->fade), 3e38f);
            }
            if (out->nc > 3) o[3] = 1;
        }
}

// One Sousa pass (thesis listing A.7 / shaders/sousa/blur.frag) on channel 0.
static inline float ref_sousa_tap_sum(const gimg *src, float px, float py, const float light[2],
                                      int taps, float step, float brightness) {
    float v[2] = {light[0] - px, light[1] - py};
    float l = sqrtf(v[0] * v[0] + v[1] * v[1]);
    float stp[2] = {0, 0};
    if (l > 0) stp[0] = v[0] * (step / l), stp[1] = v[1] * (step / l);
    float max_steps = l / step, sum = 0, p[2] = {px, py}, t[4];
    for (int i = 0; i < taps; i++) {
        if (i > 0 && (float)i >= max_steps) break;
        ref_bilinear(src, p[0], p[1], t);
        sum += t[0];
        p[0] += stp[0], p[1] += stp[1];
    }
    return fminf(sum * brightness, 1e30f);
}

static inline void ref_sousa_pass(const gimg *src, const float light[2], int taps, float step,
                                  float brightness, gimg *out) {
    for (int y = 0; y < out->h; y++)
        for (int x = 0; x < out->w; x++)
            gimg_at(out, x, y)[0] = ref_sousa_tap_sum(src, (x + 0.5f) / out->w, (y + 0.5f) / out->h,
                                                      light, taps, step, brightness);
}

// The whole chain: mask -> pass 1 (TAPS^-1) -> pass 2 (TAPS^-2) at the mask's
// size -> pass 3 (TAPS^-3) at the output size, added to hdr tinted and faded.
static inline void ref_sousa(const gimg *mask, const gimg *hdr, const float light[2], int taps,
                             float brightness, const float tint[3], float fade, gimg *out) {
    gimg t1 = gimg_new(mask->w, mask->h, 1), t2 = gimg_new(mask->w, mask->h, 1);
    ref_sousa_pass(mask, light, taps, (float)pow(taps, -1), brightness, &t1);
    ref_sousa_pass(&t1, light, taps, (float)pow(taps, -2), brightness, &t2);
    float step3 = (float)pow(taps, -3);
    for (int y = 0; y < out->h; y++)
        for (int x = 0; x < out->w; x++) {
            float s = ref_sousa_tap_sum(&t2, (x + 0.5f) / out->w, (y + 0.5f) / out->h, light, taps,
                                        step3, brightness);
            float *o = gimg_at(out, x, y);
            const float *hp = gimg_at(hdr, x, y);
            for (int c = 0; c < 3; c++)
                o[c] = fminf(hp[c] + tint[c] * (s * fade), 3e38f);
        }
    free(t1.px);
    free(t2.px);
}

// ---- GL helpers --------------------------------------------------------

// A float texture from a gimg (1 -> R32F, else RGBA32F), linear, zero border.
static inline GLuint gl_texture_from(const gimg *g) {
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, g->nc == 1 ? GL_R32F : GL_RGBA32F, g->w, g->h);
    glTextureSubImage2D(t, 0, 0, 0, g->w, g->h, g->nc == 1 ? GL_RED : GL_RGBA, GL_FLOAT, g->px);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    glTextureParameterfv(t, GL_TEXTURE_BORDER_COLOR, (const float[4]){0, 0, 0, 0});
    return t;
}

// Reads a texture into a gimg of nc channels (1 or 4), GL orientation.
static inline gimg gl_read(GLuint tex, int w, int h, int nc) {
    gimg g = gimg_new(w, h, nc);
    glGetTextureImage(tex, 0, nc == 1 ? GL_RED : GL_RGBA, GL_FLOAT,
                      (GLsizei)((size_t)w * h * nc * sizeof(float)), g.px);
    return g;
}

static inline int gimg_nonfinite(const gimg *g) {
    int n = 0;
    for (size_t i = 0; i < (size_t)g->w * g->h * g->nc; i++)
        n += !isfinite(g->px[i]);
    return n;
}

// Max |a - b| / max(1, |b|) over the first `nc` channels: absolute for
// values up to 1, relative above (b is the reference).
static inline double gimg_max_err(const gimg *a, const gimg *b, int nc) {
    double m = 0;
    for (int y = 0; y < a->h; y++)
        for (int x = 0; x < a->w; x++)
            for (int c = 0; c < nc; c++) {
                double r = gimg_at(b, x, y)[c];
                double d = fabs((double)gimg_at(a, x, y)[c] - r) / fmax(1.0, fabs(r));
                if (!(d <= m)) m = d; // NaN propagates as a failure
            }
    return m;
}

// Max |a - b| over the first `nc` channels.
static inline double gimg_max_diff(const gimg *a, const gimg *b, int nc) {
    double m = 0;
    for (int y = 0; y < a->h; y++)
        for (int x = 0; x < a->w; x++)
            for (int c = 0; c < nc; c++) {
                double d = fabs((double)gimg_at(a, x, y)[c] - gimg_at(b, x, y)[c]);
                if (!(d <= m)) m = d; // NaN propagates as a failure
            }
    return m;
}

// Deterministic pseudo-random numbers in [0, 1).
static inline float gt_rand(uint32_t *s) {
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) / 16777216.0f;
}

// ---- in-process rendering -------------------------------------------------

// Parses `json` (a scene) into *sc; exits on failure (a test bug).
static inline void gt_scene(const char *json, st_scene *sc) {
    st_err err = {0};
    memset(sc, 0, sizeof *sc);
    if (!st_scene_parse(json, strlen(json), ST_TEST_SCRATCH "/inline.json", sc, &err)) {
        fprintf(stderr, "scene: %s\n%s\n", err.msg, json);
        exit(1);
    }
}

static inline st_world *gt_world(const st_scene *sc) {
    st_err err = {0};
    st_world *w = st_world_create(sc, NULL, &err);
    if (!w) {
        fprintf(stderr, "world: %s\n", err.msg);
        exit(1);
    }
    return w;
}

// Renders `frames` frames and reads the image (top row first).
static inline bool gt_frames(st_world *w, int frames, st_image *img) {
    st_err err = {0};
    for (int i = 0; i < frames; i++)
        if (!st_world_frame(w, &err)) {
            fprintf(stderr, "frame: %s\n", err.msg);
            return false;
        }
    st_image_free(img);
    if (!st_world_read(w, img, &err)) {
        fprintf(stderr, "read: %s\n", err.msg);
        return false;
    }
    return true;
}

// A test scene of res x res pixels as JSON in buf: `camera` (a JSON object),
// `lights` and `geometry` (JSON array contents), an optional medium, and
// `module` with `params` (params NULL: no module).
static inline const char *gt_scene_json(char *buf, size_t n, int res, const char *camera,
                                        const char *lights, const char *geometry,
                                        const char *medium, const char *module,
                                        const char *params) {
    snprintf(buf, n,
             "{\"image\": {\"width\": %d, \"height\": %d},\n \"camera\": %s,\n \"lights\": [%s],\n"
             " \"geometry\": [%s],\n%s%s%s \"modules\": [%s%s%s%s%s]}\n",
             res, res, camera, lights, geometry, medium ? " \"medium\": " : "",
             medium ? medium : "", medium ? ",\n" : "", params ? "{\"name\": \"" : "",
             params ? module : "", params ? "\", \"params\": {" : "", params ? params : "",
             params ? "}}" : "");
    return buf;
}

// The scene with a god-ray module minus the same scene without it (the
// medium also dims the surfaces, so the baseline keeps it), and the first
// light's screen projection in the first world.
typedef struct {
    st_image with, without, effect;
    st_godray_light light;
} gt_pair;

static inline void gt_pair_free(gt_pair *r) {
    st_image_free(&r->with);
    st_image_free(&r->without);
    st_image_free(&r->effect);
}

static inline bool gt_render_pair(const char *json_with, const char *json_without, gt_pair *r) {
    memset(r, 0, sizeof *r);
    st_scene a, b;
    gt_scene(json_with, &a);
    gt_scene(json_without, &b);
    st_world *wa = gt_world(&a), *wb = gt_world(&b);
    bool ok = gt_frames(wa, 1, &r->with) && gt_frames(wb, 1, &r->without);
    const st_camera *c = st_world_camera(wa);
    if (a.num_lights > 0)
        r->light = st_godray_project(c->view_proj, c->near_z, a.width, a.height,
                                     a.lights[0].position, 0.5);
    st_world_destroy(wa);
    st_world_destroy(wb);
    st_scene_free(&a);
    st_scene_free(&b);
    if (!ok) return false;
    st_err err = {0};
    size_t n = (size_t)r->with.width * r->with.height * 3;
    if (!st_image_alloc(&r->effect, r->with.width, r->with.height, 3, &err)) return false;
    for (size_t i = 0; i < n; i++)
        r->effect.data[i] = r->with.data[i] - r->without.data[i];
    return true;
}

// `strahl render --stats=json --frames 2` of the scene `json`: per pass of
// `module` (at most max), its name and counts. Returns how many passes were
// listed, -1 when the command or its output failed.
typedef struct {
    char pass[64];
    int runs, skipped, culled;
} gt_pass_count;

static inline int gt_cli_pass_stats(const char *json, const char *module, gt_pass_count *out,
                                    int max) {
    char path[512], exr[512];
    int rc, n = 0;
    snprintf(path, sizeof path, "%s/%s_idle.json", ST_TEST_SCRATCH, module);
    snprintf(exr, sizeof exr, "%s/%s_idle.exr", ST_TEST_SCRATCH, module);
    st_test_write(path, json);
    cJSON *j = st_test_stats_json(path, exr, "--frames 2", &rc);
    if (rc != 0 || !j) {
        cJSON_Delete(j);
        return -1;
    }
    cJSON *p, *passes = cJSON_GetObjectItem(j, "passes");
    cJSON_ArrayForEach(p, passes) {
        if (strcmp(cJSON_GetObjectItem(p, "module")->valuestring, module) || n >= max) continue;
        snprintf(out[n].pass, sizeof out[n].pass, "%s",
                 cJSON_GetObjectItem(p, "pass")->valuestring);
        out[n].runs = cJSON_GetObjectItem(p, "runs")->valueint;
        out[n].skipped = cJSON_GetObjectItem(p, "skipped")->valueint;
        out[n].culled = cJSON_GetObjectItem(p, "culled")->valueint;
        n++;
    }
    cJSON_Delete(j);
    return n;
}

// Sums of a module's pass stats whose name starts with `pass` ("blur" matches
// "blur" and "blur[1]"); returns how many passes matched.
static inline int gt_stats(const st_world *w, const char *module, const char *pass, unsigned *runs,
                           unsigned *skipped, unsigned *culled) {
    int n = 0;
    *runs = *skipped = *culled = 0;
    size_t l = strlen(pass);
    for (int i = 0; i < st_world_num_pass_stats(w); i++) {
        const st_pass_stats *s = st_world_pass_stats(w, i);
        if (strcmp(s->module, module) || strncmp(s->pass, pass, l) ||
            (s->pass[l] && s->pass[l] != '['))
            continue;
        n++;
        *runs += s->runs, *skipped += s->skipped, *culled += s->culled;
    }
    return n;
}

static inline double gt_image_sum(const st_image *a) {
    double s = 0;
    for (size_t i = 0; i < (size_t)a->width * a->height * a->channels; i++)
        s += a->data[i];
    return s;
}

// max |a - b| over all values.
static inline double gt_image_max_diff(const st_image *a, const st_image *b) {
    double m = 0;
    for (size_t i = 0; i < (size_t)a->width * a->height * a->channels; i++) {
        double d = fabs((double)a->data[i] - b->data[i]);
        if (!(d <= m)) m = d;
    }
    return m;
}

// ---- fading along a camera path ------------------------------------------------

// Effect energy (the scene with the module minus without it) along a camera path
// pose(t), t in [0, 1], in `steps` steps: the largest step-to-step change,
// where it becomes exactly zero, and whether the module's `last` pass is
// skipped and its `first` pass culled exactly then.
typedef struct {
    double peak, max_jump, last;
    int zero_from, nonfinite, skips_ok;
} sweep_result;

static inline sweep_result gt_sweep(const char *module, const char *last, const char *first,
                                    const char *json_with, const char *json_without, int steps,
                                    void (*pose)(double, double[3], double[3])) {
    st_scene sa, sb;
    gt_scene(json_with, &sa);
    gt_scene(json_without, &sb);
    st_world *wa = gt_world(&sa), *wb = gt_world(&sb);
    st_image ia = {0}, ib = {0};
    sweep_result r = {0, 0, 0, -1, 0, 1};
    double prev = -1;
    for (int s = 0; s <= steps; s++) {
        double pos[3], tgt[3];
        pose((double)s / steps, pos, tgt);
        const float fp[3] = {(float)pos[0], (float)pos[1], (float)pos[2]},
                    ft[3] = {(float)tgt[0], (float)tgt[1], (float)tgt[2]}, up[3] = {0, 1, 0};
        st_world_set_camera(wa, fp, ft, up);
        st_world_set_camera(wb, fp, ft, up);
        st_world_reset_stats(wa);
        if (!gt_frames(wa, 1, &ia) || !gt_frames(wb, 1, &ib)) break;
        r.nonfinite += !st_test_all_finite(&ia);
        double e = gt_image_sum(&ia) - gt_image_sum(&ib);
        if (prev >= 0) r.max_jump = fmax(r.max_jump, fabs(e - prev));
        r.peak = fmax(r.peak, e);
        prev = r.last = e;
        unsigned runs, skipped, culled, oruns, oskipped, oculled;
        gt_stats(wa, module, last, &runs, &skipped, &culled);
        gt_stats(wa, module, first, &oruns, &oskipped, &oculled);
        bool zero = gt_image_max_diff(&ia, &ib) == 0;
        if (zero && r.zero_from < 0) r.zero_from = s;
        if (!zero) r.zero_from = -1;
        if (zero != (skipped == 1 && runs == 0) || (zero && oculled != 1)) r.skips_ok = 0;
    }
    st_image_free(&ia);
    st_image_free(&ib);
    st_world_destroy(wa);
    st_world_destroy(wb);
    st_scene_free(&sa);
    st_scene_free(&sb);
    return r;
}

// No popping: along the same path, 4x finer steps must shrink the largest
// step-to-step change (a jump would stay the same size), and the shafts
// reach exactly 0, with the passes skipped and culled from then on.
static inline void gt_check_sweep(const char *what, const char *module, const char *last,
                                  const char *first, const char *json_with,
                                  const char *json_without, int steps,
                                  void (*pose)(double, double[3], double[3])) {
    sweep_result c = gt_sweep(module, last, first, json_with, json_without, steps, pose),
                 f = gt_sweep(module, last, first, json_with, json_without, 4 * steps, pose);
    printf("%s: peak energy %.4g; largest change per step %.4g at %d steps, %.4g at %d steps "
           "(ratio %.2f); "
           "zero from t = %.3f\n",
           what, f.peak, c.max_jump, steps, f.max_jump, 4 * steps, f.max_jump / c.max_jump,
           (double)f.zero_from / (4 * steps));
    CHECK(c.nonfinite == 0 && f.nonfinite == 0, "%s: finite", what);
    CHECK(f.peak > 0, "%s: visible at the start", what);
    CHECK(f.max_jump < 0.5 * c.max_jump, "%s: continuous: %g at 4x finer steps vs %g", what,
          f.max_jump, c.max_jump);
    CHECK(f.zero_from > 0 && f.last == 0 && c.last == 0, "%s: fades to exactly 0", what);
    CHECK(c.skips_ok && f.skips_ok, "%s: %s skipped and %s culled exactly when the effect is 0",
          what, last, first);
}

// Camera paths for the fade tests (t in [0, 1]), light near the origin seen
// from z = 5. Slide sideways: the light leaves the screen at x = 5 tan 20 =
// 1.82 and is beyond the 0.5-screen-height margin from x = 3.64.
static inline void godray_pose_slide(double t, double pos[3], double tgt[3]) {
    double x = 4.5 * t;
    pos[0] = x, pos[1] = 0, pos[2] = 5;
    tgt[0] = x, tgt[1] = 0, tgt[2] = 0;
}
// Turn around on the spot: the light goes off to the side (20 degrees),
// fades out by 36 degrees, and ends behind the camera.
static inline void godray_pose_turn(double t, double pos[3], double tgt[3]) {
    double th = t * M_PI;
    pos[0] = 0, pos[1] = 0, pos[2] = 5;
    tgt[0] = sin(th), tgt[1] = 0, tgt[2] = 5 - cos(th);
}
// Walk forward past the light: it ends up behind the camera.
static inline void godray_pose_walk(double t, double pos[3], double tgt[3]) {
    double z = 5 - 6 * t;
    pos[0] = 0.3, pos[1] = 0.2, pos[2] = z;
    tgt[0] = 0.3, tgt[1] = 0.2, tgt[2] = z - 1;
}

#endif
