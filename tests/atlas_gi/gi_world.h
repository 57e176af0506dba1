// In-process worlds for tests that move the camera or change parameters
// between frames: a headless context, a scene parsed from a string, frames,
// per-pass run counts, and the image sampled at projected world points.
#ifndef GI_WORLD_H
#define GI_WORLD_H
#include "gi_test.h"
#include "st_world.h"

typedef struct gi_world {
    st_scene scene;
    st_world *w;
} gi_world;

static inline int gi_world_open(gi_world *g, const char *json) {
    st_err err = {0};
    memset(g, 0, sizeof *g);
    if (!st_scene_parse(json, strlen(json), ST_TEST_SCRATCH "/inline.json", &g->scene, &err)) {
        CHECK(0, "scene: %s", err.msg);
        return 0;
    }
    st_world_opts o = {.timing = true};
    g->w = st_world_create(&g->scene, &o, &err);
    CHECK(g->w != NULL, "world: %s", err.msg);
    return g->w != NULL;
}

static inline void gi_world_close(gi_world *g) {
    st_world_destroy(g->w);
    st_scene_free(&g->scene);
}

static inline int gi_frame(gi_world *g) {
    st_err err = {0};
    bool ok = st_world_frame(g->w, &err);
    CHECK(ok, "frame: %s", err.msg);
    glFinish();
    return ok;
}

// Runs of a pass so far (module, pass name), -1 if there is no such pass.
static inline int gi_runs(gi_world *g, const char *module, const char *pass, bool *ran_last) {
    for (int i = 0; i < st_world_num_pass_stats(g->w); i++) {
        const st_pass_stats *s = st_world_pass_stats(g->w, i);
        if (strcmp(s->module, module) || strcmp(s->pass, pass)) continue;
        if (ran_last) *ran_last = s->ran_last_frame;
        return (int)s->runs;
    }
    return -1;
}

// Frames until atlas_gi's gather stops running (converged), at most max.
static inline int gi_converge(gi_world *g, int max) {
    for (int i = 0; i < max; i++) {
        bool ran = true;
        if (!gi_frame(g)) return -1;
        gi_runs(g, "atlas_gi", "gather", &ran);
        if (!ran) return i + 1;
    }
    return -1;
}

typedef struct gi_pose {
    double pos[3], target[3], fov;
} gi_pose;

static inline void gi_set_pose(gi_world *g, const gi_pose *p) {
    float pos[3], tgt[3], up[3] = {0, 1, 0};
    for (int k = 0; k < 3; k++)
        pos[k] = (float)p->pos[k], tgt[k] = (float)p->target[k];
    st_world_camera(g->w)->fov_y = (float)p->fov;
    st_world_set_camera(g->w, pos, tgt, up);
}

// Bilinear lookup of channel c of the image at the projection of world
// point x under pose p (the pinhole convention of docs/physics.md). Returns -1 if
// the point is not at least 3 pixels inside the image.
static inline double gi_sample_point(const st_image *img, const gi_pose *p, const double x[3],
                                     int c) {
    const double up[3] = {0, 1, 0};
    st_test_cam cam = st_test_camera(p->pos, p->target, up, p->fov, img->width, img->height);
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = x[k] - cam.pos[k];
    double z = d[0] * cam.f[0] + d[1] * cam.f[1] + d[2] * cam.f[2];
    if (z <= 0) return -1;
    double sx =
        (d[0] * cam.r[0] + d[1] * cam.r[1] + d[2] * cam.r[2]) / z / (cam.tan_half * cam.aspect);
    double sy = (d[0] * cam.u[0] + d[1] * cam.u[1] + d[2] * cam.u[2]) / z / cam.tan_half;
    double px = (sx + 1) / 2 * img->width - 0.5, py = (1 - sy) / 2 * img->height - 0.5;
    if (px < 3 || py < 3 || px > img->width - 4 || py > img->height - 4) return -1;
    int i = (int)floor(px), j = (int)floor(py);
    double fx = px - i, fy = py - j;
    return (1 - fy) * ((1 - fx) * st_image_px(img, i, j)[c] + fx * st_image_px(img, i + 1, j)[c]) +
           fy * ((1 - fx) * st_image_px(img, i, j + 1)[c] + fx * st_image_px(img, i + 1, j + 1)[c]);
}

static inline int gi_read(gi_world *g, st_image *img) {
    st_err err = {0};
    bool ok = st_world_read(g->w, img, &err);
    CHECK(ok, "read: %s", err.msg);
    if (ok) CHECK(st_test_all_finite(img), "finite image");
    return ok;
}
#endif
