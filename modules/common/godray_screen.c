// See godray_screen.h.
#include "godray_screen.h"
#include <math.h>

static double smoothstep(double e0, double e1, double x) {
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

godray_light godray_project(const float *view_proj, float near_z, int width, int height,
                            const float p[3], double margin) {
    godray_light r = {{0.5f, 0.5f}, 0.0f, 0.0f};
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

void godray_tint(const st_light_desc *lights, int num_lights, int k, float out[3]) {
    float mx = 0;
    for (int i = 0; i < num_lights; i++)
        for (int c = 0; c < 3; c++)
            if (lights[i].intensity[c] > mx) mx = lights[i].intensity[c];
    for (int c = 0; c < 3; c++) {
        float v = lights[k].intensity[c];
        out[c] = mx > 0 && v > 0 ? v / mx : 0.0f;
    }
}

bool godray_medium_active(const st_scene *s) {
    return s->medium.present &&
           (s->medium.sigma_s[0] > 0 || s->medium.sigma_s[1] > 0 || s->medium.sigma_s[2] > 0);
}

godray_light godray_light_state(const st_frame *f, int k, double margin, float tint[3]) {
    godray_tint(f->scene->lights, f->scene->num_lights, k, tint);
    return godray_project(f->view_proj, f->near_z, f->width, f->height,
                          f->scene->lights[k].position, margin);
}

bool godray_light_active(const st_frame *f, int k, double margin) {
    if (!godray_medium_active(f->scene)) return false;
    float tint[3];
    godray_light l = godray_light_state(f, k, margin, tint);
    return l.fade > 0 && (tint[0] > 0 || tint[1] > 0 || tint[2] > 0);
}
