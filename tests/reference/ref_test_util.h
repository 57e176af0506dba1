// Helpers for the reference tests: scenes built in memory from quads and
// boxes, the camera convention restated independently of the renderer, and
// image statistics.
#ifndef REF_TEST_UTIL_H
#define REF_TEST_UTIL_H
#include "st_test.h" // first: it sets the feature macros
#include "reference/ref.h"

static inline void v3(float o[3], double x, double y, double z) {
    o[0] = (float)x, o[1] = (float)y, o[2] = (float)z;
}

// An empty scene of w x h pixels with the given camera.
static inline void scene_init(st_scene *s, int w, int h, const double pos[3],
                              const double target[3], const double up[3], double fov_y,
                              double far_z) {
    memset(s, 0, sizeof *s);
    snprintf(s->path, sizeof s->path, "in-memory");
    s->width = w, s->height = h;
    v3(s->camera.position, pos[0], pos[1], pos[2]);
    v3(s->camera.target, target[0], target[1], target[2]);
    v3(s->camera.up, up[0], up[1], up[2]);
    s->camera.fov_y = (float)fov_y;
    s->camera.near_z = 0.01f;
    s->camera.far_z = (float)far_z;
}

static inline st_mesh *add_quad(st_scene *s, const double c[3], const double u[3],
                                const double v[3], double albedo, double emission) {
    float fc[3], fu[3], fv[3];
    v3(fc, c[0], c[1], c[2]), v3(fu, u[0], u[1], u[2]), v3(fv, v[0], v[1], v[2]);
    st_mesh m;
    st_mesh_quad(&m, fc, fu, fv);
    v3(m.albedo, albedo, albedo, albedo);
    v3(m.emission, emission, emission, emission);
    st_err err = {0};
    if (!m.positions || !st_scene_add_mesh(s, &m, &err)) {
        fprintf(stderr, "add_quad: %s\n", err.msg);
        exit(1);
    }
    return &s->meshes[s->num_meshes - 1];
}

static inline void add_light(st_scene *s, const double p[3], double intensity) {
    st_light_desc l = {0}; // a point light: every other field zero, not stack garbage
    v3(l.position, p[0], p[1], p[2]);
    v3(l.intensity, intensity, intensity, intensity);
    st_err err = {0};
    if (!st_scene_add_light(s, &l, &err)) exit(1);
}

static inline void set_medium(st_scene *s, double sigma_s, double sigma_a, st_phase_kind phase,
                              double g) {
    s->medium.present = true;
    v3(s->medium.sigma_s, sigma_s, sigma_s, sigma_s);
    v3(s->medium.sigma_a, sigma_a, sigma_a, sigma_a);
    s->medium.phase = phase;
    s->medium.g = (float)g;
}

// docs/physics.md's pinhole, written out again here so the renderer's camera is
// checked against the contract rather than against itself.
static inline void contract_ray(const st_scene *s, int i, int j, double dir[3]) {
    const st_camera_desc *c = &s->camera;
    double f[3], r[3], u[3], up[3] = {c->up[0], c->up[1], c->up[2]};
    for (int k = 0; k < 3; k++)
        f[k] = (double)c->target[k] - c->position[k];
    double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; k++)
        f[k] /= fl;
    r[0] = f[1] * up[2] - f[2] * up[1], r[1] = f[2] * up[0] - f[0] * up[2],
    r[2] = f[0] * up[1] - f[1] * up[0];
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; k++)
        r[k] /= rl;
    u[0] = r[1] * f[2] - r[2] * f[1], u[1] = r[2] * f[0] - r[0] * f[2],
    u[2] = r[0] * f[1] - r[1] * f[0];
    double t = tan(c->fov_y * ST_PI / 360.0), aspect = (double)s->width / s->height;
    double x = (2.0 * (i + 0.5) / s->width - 1.0) * t * aspect,
           y = (1.0 - 2.0 * (j + 0.5) / s->height) * t;
    for (int k = 0; k < 3; k++)
        dir[k] = f[k] + x * r[k] + y * u[k];
    double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (int k = 0; k < 3; k++)
        dir[k] /= dl;
}

static inline bool render(const st_scene *s, const st_ref_options *o, st_image *img) {
    st_err err = {0};
    double t0 = st_now_ms();
    bool ok = st_ref_render(s, o, img, &err);
    fprintf(stderr, "  rendered %dx%d at %d spp in %.2f s\n", s->width, s->height, o->spp,
            (st_now_ms() - t0) / 1000);
    if (!ok) fprintf(stderr, "render failed: %s\n", err.msg);
    return ok;
}

#endif
