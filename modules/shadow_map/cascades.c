#include "cascades.h"
#include "st_physics.h"
#include <math.h>
#include <string.h>

static double dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize3(double a[3]) {
    double l = sqrt(dot3(a, a));
    for (int k = 0; k < 3; k++)
        a[k] /= l;
}

void sm_sun_basis(const double L[3], double u[3], double v[3]) {
    // Same rule as the GLSL: any axis not nearly parallel to L.
    double a[3] = {0, 0, 0};
    a[fabs(L[1]) < 0.9 ? 1 : 0] = 1;
    u[0] = L[1] * a[2] - L[2] * a[1], u[1] = L[2] * a[0] - L[0] * a[2],
    u[2] = L[0] * a[1] - L[1] * a[0];
    normalize3(u);
    v[0] = L[1] * u[2] - L[2] * u[1], v[1] = L[2] * u[0] - L[0] * u[2],
    v[2] = L[0] * u[1] - L[1] * u[0];
}

void sm_sun_init(sm_sun *s, const st_scene *scene, const float direction[3]) {
    memset(s, 0, sizeof *s);
    for (int k = 0; k < 3; k++)
        s->L[k] = -direction[k];
    normalize3(s->L);
    sm_sun_basis(s->L, s->u, s->v);
    double lo[3], hi[3];
    s->entry = st_directional_entry(scene, direction);
    if (!st_scene_bounds(scene, lo, hi)) {
        s->entry = 0, s->zrange = 1;
        return;
    }
    double low = INFINITY;
    for (int k = 0; k < 8; k++) {
        double c[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        low = fmin(low, dot3(c, s->L));
    }
    s->zrange = fmax((s->entry - low) * 1.01, 1e-3);
}

// The camera's basis from its view matrix (rows: right, up, -forward).
static void camera_basis(const st_frame *f, double r[3], double up[3], double fwd[3]) {
    for (int k = 0; k < 3; k++)
        r[k] = f->view[4 * k], up[k] = f->view[4 * k + 1], fwd[k] = -f->view[4 * k + 2];
}

// The view depth past which the scene has no geometry (at least near).
static double scene_depth(const st_scene *scene, const st_frame *f, const double fwd[3]) {
    double lo[3], hi[3], far_z = f->near_z * 1.01;
    if (!st_scene_bounds(scene, lo, hi)) return fmin(f->far_z, far_z);
    for (int k = 0; k < 8; k++) {
        double c[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        double d[3] = {c[0] - f->cam_pos[0], c[1] - f->cam_pos[1], c[2] - f->cam_pos[2]};
        far_z = fmax(far_z, dot3(d, fwd));
    }
    return fmin(far_z, f->far_z);
}

bool sm_sun_fit(sm_sun *s, const st_scene *scene, const st_frame *f, int cascades, double lambda,
                bool force) {
    double r[3], up[3], fwd[3];
    camera_basis(f, r, up, fwd);
    const double n = f->near_z, fz = scene_depth(scene, f, fwd);
    const double th = tan(f->fov_y * ST_PI / 360.0), aspect = (double)f->width / f->height;
    if (cascades != s->count) force = true;
    s->count = cascades;
    bool changed = force || !s->fitted;
    double z0 = n;
    for (int c = 0; c < cascades; c++) {
        double i = (double)(c + 1) / cascades;
        double z1 =
            lambda * n * pow(fz / n, i) + (1 - lambda) * (n + (fz - n) * i); // practical split
        s->far_z[c] = z1;
        // The slice's corners, their centroid and bounding radius in the light's plane.
        double cu = 0, cv = 0, pu[8], pv[8];
        for (int k = 0; k < 8; k++) {
            double z = k & 4 ? z1 : z0, x = (k & 1 ? 1 : -1) * z * th * aspect,
                   y = (k & 2 ? 1 : -1) * z * th;
            double p[3];
            for (int a = 0; a < 3; a++)
                p[a] = f->cam_pos[a] + fwd[a] * z + r[a] * x + up[a] * y;
            pu[k] = dot3(p, s->u), pv[k] = dot3(p, s->v);
            cu += pu[k] / 8, cv += pv[k] / 8;
        }
        double rad = 1e-6;
        for (int k = 0; k < 8; k++)
            rad = fmax(rad, hypot(pu[k] - cu, pv[k] - cv));
        sm_rect *fit = &s->fit[c];
        bool inside =
            hypot(cu - fit->cu, cv - fit->cv) + rad <= fit->half && rad >= 0.5 * fit->half;
        if (force || !s->fitted || !inside) {
            fit->cu = cu, fit->cv = cv, fit->half = 1.2 * rad;
            changed = true;
        }
        z0 = z1;
    }
    s->fitted = true;
    return changed;
}

void sm_sun_matrix(const sm_sun *s, int c, float out[16]) {
    const sm_rect *q = &s->fit[c];
    memset(out, 0, 16 * sizeof *out);
    for (int k = 0; k < 3; k++) {
        out[4 * k] = (float)(s->u[k] / q->half);
        out[4 * k + 1] = (float)(s->v[k] / q->half);
        out[4 * k + 2] = (float)(-2 * s->L[k] / s->zrange);
    }
    out[12] = (float)(-q->cu / q->half);
    out[13] = (float)(-q->cv / q->half);
    out[14] = (float)(2 * s->entry / s->zrange - 1);
    out[15] = 1;
}
