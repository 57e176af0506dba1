// See st_godray.h.
#include "st_godray.h"
#include "st_physics.h"
#include <math.h>

static double smoothstep(double e0, double e1, double x) {
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

st_godray_light st_godray_project(const float *view_proj, float near_z, int width, int height,
                                  const float p[3], double margin) {
    st_godray_light r = {{0.5f, 0.5f}, 0.0f, 0.0f};
    double c[4];
    for (int i = 0; i < 4; i++)
        c[i] = (double)view_proj[i] * p[0] + (double)view_proj[4 + i] * p[1] +
               (double)view_proj[8 + i] * p[2] + view_proj[12 + i];
    double near_ = near_z > 1e-6f ? near_z : 1e-6;
    r.w = (float)c[3];
    if (!(c[3] > near_) || !isfinite(c[0]) || !isfinite(c[1])) return r;
    double fade = smoothstep(near_, 2 * near_, c[3]);
    double u = 0.5 * c[0] / c[3] + 0.5, v = 0.5 * c[1] / c[3] + 0.5;
    double aspect = height > 0 ? (double)width / height : 1.0;
    double dx = (u < 0 ? -u : u > 1 ? u - 1 : 0) * aspect, dy = v < 0 ? -v : v > 1 ? v - 1 : 0;
    fade *= 1.0 - smoothstep(0.0, margin > 1e-6 ? margin : 1e-6, sqrt(dx * dx + dy * dy));
    if (!(fade > 0)) return r;
    r.fade = (float)fade;
    r.uv[0] = (float)u;
    r.uv[1] = (float)v;
    return r;
}

st_godray_light st_godray_project_dir(const float *view_proj, int width, int height,
                                      const float to_light[3], double margin) {
    st_godray_light r = {{0.5f, 0.5f}, 0.0f, 0.0f};
    double c[4];
    for (int i = 0; i < 4; i++) // w = 0: no translation
        c[i] = (double)view_proj[i] * to_light[0] + (double)view_proj[4 + i] * to_light[1] +
               (double)view_proj[8 + i] * to_light[2];
    r.w = (float)c[3];
    if (!(c[3] > 1e-12) || !isfinite(c[0]) || !isfinite(c[1])) return r;
    double u = 0.5 * c[0] / c[3] + 0.5, v = 0.5 * c[1] / c[3] + 0.5;
    double aspect = height > 0 ? (double)width / height : 1.0;
    double dx = (u < 0 ? -u : u > 1 ? u - 1 : 0) * aspect, dy = v < 0 ? -v : v > 1 ? v - 1 : 0;
    double off = sqrt(dx * dx + dy * dy); // +inf when w underflows: fade 0, never NaN
    double fade = 1.0 - smoothstep(0.0, margin > 1e-6 ? margin : 1e-6, off);
    if (!(fade > 0)) return r;
    r.fade = (float)fade;
    r.uv[0] = (float)u;
    r.uv[1] = (float)v;
    return r;
}

void st_godray_source_radiance(const st_light_desc *l, double point_radius, double out[3]) {
    double area;
    if (l->type == ST_LIGHT_DIRECTIONAL) {
        double half = 0.5 * st_light_angular_diameter(l);
        area = 2 * ST_PI * (1 - cos(half));          // the disc's solid angle
        if (!(area > 0)) area = ST_PI * half * half; // cos rounding at tiny angles
    } else {
        area = ST_PI * point_radius * point_radius; // the sphere's projected area
    }
    for (int c = 0; c < 3; c++)
        out[c] = area > 0 && l->intensity[c] > 0 ? l->intensity[c] / area : 0.0;
}

void st_godray_tint(const st_light_desc *lights, int num_lights, int k, double point_radius,
                    float out[3]) {
    double mx = 0, L[3], Lk[3] = {0, 0, 0};
    for (int i = 0; i < num_lights; i++) {
        st_godray_source_radiance(&lights[i], point_radius, L);
        for (int c = 0; c < 3; c++) {
            if (L[c] > mx) mx = L[c];
            if (i == k) Lk[c] = L[c];
        }
    }
    for (int c = 0; c < 3; c++)
        out[c] = mx > 0 && Lk[c] > 0 ? (float)(Lk[c] / mx) : 0.0f;
}

bool st_godray_medium_active(const st_scene *s) {
    return s->medium.present &&
           (s->medium.sigma_s[0] > 0 || s->medium.sigma_s[1] > 0 || s->medium.sigma_s[2] > 0);
}

// Where light k lands on the screen and its fade.
static st_godray_light light_screen(const st_frame *f, int k, double margin) {
    const st_light_desc *l = &f->scene->lights[k];
    if (l->type == ST_LIGHT_DIRECTIONAL) {
        const float to_light[3] = {-l->direction[0], -l->direction[1], -l->direction[2]};
        return st_godray_project_dir(f->view_proj, f->width, f->height, to_light, margin);
    }
    return st_godray_project(f->view_proj, f->near_z, f->width, f->height, l->position, margin);
}

st_godray_light st_godray_light_state(const st_frame *f, int k, double margin, double point_radius,
                                      float tint[3]) {
    st_godray_tint(f->scene->lights, f->scene->num_lights, k, point_radius, tint);
    return light_screen(f, k, margin);
}

bool st_godray_light_active(const st_frame *f, int k, double margin) {
    if (!st_godray_medium_active(f->scene)) return false;
    const st_light_desc *d = &f->scene->lights[k];
    if (!(d->intensity[0] > 0 || d->intensity[1] > 0 || d->intensity[2] > 0)) return false;
    return light_screen(f, k, margin).fade > 0;
}
