// Orbit and fly camera for strahl view. Angles are measured in a basis built
// from the scene's up vector, so scenes with any up direction work.
#define _GNU_SOURCE
#include "view.h"
#include <math.h>
#include <string.h>

static void sub(const float *a, const float *b, float *o) {
    o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2];
}
static float dot(const float *a, const float *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static void cross(const float *a, const float *b, float *o) {
    float t[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    memcpy(o, t, sizeof t);
}
static float norm(float *v) {
    float l = sqrtf(dot(v, v));
    if (l > 0) v[0] /= l, v[1] /= l, v[2] /= l;
    return l;
}

// Orthonormal basis (x, z horizontal, u up) from the up vector.
static void basis(const view_cam *c, float x[3], float z[3], float u[3]) {
    memcpy(u, c->up, 3 * sizeof(float));
    if (norm(u) == 0) u[0] = 0, u[1] = 1, u[2] = 0;
    const float ref[3] = {1, 0, 0}, alt[3] = {0, 0, 1};
    cross(fabsf(u[0]) < 0.9f ? ref : alt, u, z);
    norm(z);
    cross(u, z, x);
}

// v = r (cos p (cos y x + sin y z) + sin p u)
static void to_angles(const view_cam *c, const float *v, float *yaw, float *pitch, float *r) {
    float x[3], z[3], u[3], d[3] = {v[0], v[1], v[2]};
    basis(c, x, z, u);
    *r = norm(d);
    float s = dot(d, u);
    *pitch = asinf(s < -1 ? -1 : s > 1 ? 1 : s);
    *yaw = atan2f(dot(d, z), dot(d, x));
}

static void from_angles(const view_cam *c, float yaw, float pitch, float r, float *v) {
    float x[3], z[3], u[3];
    basis(c, x, z, u);
    for (int k = 0; k < 3; k++)
        v[k] = r * (cosf(pitch) * (cosf(yaw) * x[k] + sinf(yaw) * z[k]) + sinf(pitch) * u[k]);
}

void view_cam_init(view_cam *c, const st_camera_desc *d) {
    memset(c, 0, sizeof *c);
    memcpy(c->pos, d->position, sizeof c->pos);
    memcpy(c->target, d->target, sizeof c->target);
    memcpy(c->up, d->up, sizeof c->up);
    float v[3];
    sub(c->target, c->pos, v);
    // About the scene's size per 2 s; a scene camera 3.4 m away moves 1.7 m/s.
    float l = sqrtf(dot(v, v));
    c->speed = l > 1e-3f ? 0.5f * l : 1.0f;
}

void view_cam_rotate(view_cam *c, float dyaw, float dpitch) {
    const float lim = 89.0f * (float)M_PI / 180.0f, k = (float)M_PI / 180.0f;
    float v[3], yaw, pitch, r;
    if (c->fly) {
        sub(c->target, c->pos, v);
    } else {
        sub(c->pos, c->target, v);
    }
    to_angles(c, v, &yaw, &pitch, &r);
    if (r <= 0) return;
    yaw += dyaw * k;
    pitch += dpitch * k;
    pitch = pitch < -lim ? -lim : pitch > lim ? lim : pitch;
    from_angles(c, yaw, pitch, r, v);
    for (int i = 0; i < 3; i++) {
        if (c->fly)
            c->target[i] = c->pos[i] + v[i];
        else
            c->pos[i] = c->target[i] + v[i];
    }
}

void view_cam_move(view_cam *c, float fwd, float right, float up) {
    float f[3], r[3], u[3] = {c->up[0], c->up[1], c->up[2]};
    sub(c->target, c->pos, f);
    norm(f);
    if (norm(u) == 0) u[1] = 1;
    cross(f, u, r);
    if (norm(r) == 0) return;
    for (int i = 0; i < 3; i++) {
        float d = fwd * f[i] + right * r[i] + up * u[i];
        c->pos[i] += d;
        c->target[i] += d;
    }
}

void view_cam_dolly(view_cam *c, float factor) {
    if (!(factor > 0)) return;
    float v[3];
    sub(c->pos, c->target, v);
    // Keep at least 1 mm so the direction survives repeated zooming in.
    if (sqrtf(dot(v, v)) * factor < 1e-3f) return;
    for (int i = 0; i < 3; i++)
        c->pos[i] = c->target[i] + v[i] * factor;
}
