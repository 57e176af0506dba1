// Helpers for headless render tests: write a scene, run `strahl render`,
// read the EXR back, and reproduce the camera's pixel rays on the CPU (the
// pinhole convention of docs/physics.md) for analytic expectations.
#ifndef ST_TEST_RENDER_H
#define ST_TEST_RENDER_H
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "st_image.h"
#include "st_test.h"

static inline void st_test_write(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(1);
    }
    fputs(text, f);
    fclose(f);
}

// Renders scene -> out (EXR), returns the exit code; extra is appended to
// the command line. With the point filter: these tests compare pixels with
// what the ray through the pixel centre sees (st_test_ray); `--filter box` in
// extra overrides it.
static inline int st_test_render(const char *scene, const char *out, const char *extra) {
    unlink(out);
    return st_test_sh("%s render %s -o %s --filter point %s", ST_TEST_STRAHL, scene, out,
                      extra ? extra : "");
}

static inline int st_test_read(const char *path, st_image *img) {
    st_err err = {0};
    if (!st_image_read_exr(path, img, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return 0;
    }
    return 1;
}

typedef struct {
    double pos[3], f[3], r[3], u[3];
    double tan_half, aspect;
    int w, h;
} st_test_cam;

static inline void st_v_norm(double *v) {
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v[0] /= l, v[1] /= l, v[2] /= l;
}
static inline void st_v_cross(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static inline st_test_cam st_test_camera(const double pos[3], const double target[3],
                                         const double up[3], double fov_y, int w, int h) {
    st_test_cam c;
    for (int k = 0; k < 3; k++)
        c.pos[k] = pos[k], c.f[k] = target[k] - pos[k];
    st_v_norm(c.f);
    st_v_cross(c.f, up, c.r);
    st_v_norm(c.r);
    st_v_cross(c.r, c.f, c.u);
    c.tan_half = tan(fov_y * M_PI / 360.0);
    c.aspect = (double)w / h;
    c.w = w, c.h = h;
    return c;
}

// Direction through the centre of pixel (i, j), j = 0 the top row.
static inline void st_test_ray(const st_test_cam *c, int i, int j, double d[3]) {
    double x = (2.0 * (i + 0.5) / c->w - 1.0) * c->tan_half * c->aspect;
    double y = (1.0 - 2.0 * (j + 0.5) / c->h) * c->tan_half;
    for (int k = 0; k < 3; k++)
        d[k] = c->f[k] + x * c->r[k] + y * c->u[k];
    st_v_norm(d);
}

// Ray / axis-aligned box: entry distance, or -1.
static inline double st_test_ray_box(const double o[3], const double d[3], const double mn[3],
                                     const double mx[3]) {
    double t0 = -1e30, t1 = 1e30;
    for (int k = 0; k < 3; k++) {
        if (fabs(d[k]) < 1e-15) {
            if (o[k] < mn[k] || o[k] > mx[k]) return -1;
            continue;
        }
        double a = (mn[k] - o[k]) / d[k], b = (mx[k] - o[k]) / d[k];
        if (a > b) {
            double t = a;
            a = b;
            b = t;
        }
        if (a > t0) t0 = a;
        if (b < t1) t1 = b;
    }
    return t0 <= t1 && t1 > 0 ? (t0 > 0 ? t0 : 0) : -1;
}

static inline int st_test_all_finite(const st_image *img) {
    return st_image_count_nonfinite(img) == 0;
}

#endif
