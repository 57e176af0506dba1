// Screen-space light handling shared by the image-space god-ray modules
// (mitchell, sousa) and their tests: where a point light lands on the screen,
// how strongly its shafts are faded, and the light's tint.
//
// Fade rules (docs/architecture.md: nothing runs that the scene does not need):
// - behind the camera or at its position (view depth w <= near): 0, and the
//   projected position is never computed, so no mirrored rays;
// - between near and 2 near of view depth: smoothstep up to 1 (the disc and
//   the projection are unreliable that close to the camera plane);
// - off screen: 1 - smoothstep(0, margin, d), d the distance of the projected
//   position outside the [0,1]^2 screen in screen heights (aspect-corrected).
// The product is continuous in the light's position, so shafts never pop, and
// a fade of exactly 0 lets the module skip its passes.
#ifndef GODRAY_SCREEN_H
#define GODRAY_SCREEN_H
#include "st_scene.h"
#include <math.h>

typedef struct godray_light {
    float uv[2]; // texture coordinates of the light, (0,0) bottom left; (0.5,0.5) when fade = 0
    float fade;  // [0, 1]
    float w;     // view depth (clip w), metres in front of the camera
} godray_light;

static inline double godray_smoothstep(double e0, double e1, double x) {
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

// view_proj column-major (GL); p the light's world position.
static inline godray_light godray_project(const float *view_proj, float near_z, int width, int height,
                                          const float p[3], double margin) {
    godray_light r = {{0.5f, 0.5f}, 0.0f, 0.0f};
    double c[4];
    for (int i = 0; i < 4; i++)
        c[i] = (double)view_proj[i] * p[0] + (double)view_proj[4 + i] * p[1] + (double)view_proj[8 + i] * p[2] +
               view_proj[12 + i];
    double near_ = near_z > 1e-6f ? near_z : 1e-6;
    r.w = (float)c[3];
    if (!(c[3] > near_) || !isfinite(c[0]) || !isfinite(c[1])) return r;
    double fade = godray_smoothstep(near_, 2 * near_, c[3]);
    double u = 0.5 * c[0] / c[3] + 0.5, v = 0.5 * c[1] / c[3] + 0.5;
    double aspect = height > 0 ? (double)width / height : 1.0;
    double dx = (u < 0 ? -u : u > 1 ? u - 1 : 0) * aspect, dy = v < 0 ? -v : v > 1 ? v - 1 : 0;
    fade *= 1.0 - godray_smoothstep(0.0, margin > 1e-6 ? margin : 1e-6, sqrt(dx * dx + dy * dy));
    if (!(fade > 0)) return r;
    r.fade = (float)fade;
    r.uv[0] = (float)u;
    r.uv[1] = (float)v;
    return r;
}

// A light's tint: its intensity divided by the largest channel of any light in
// the scene, so the brightest light is at most 1 per channel (the thesis draws
// the light object "in the light colour" into an 8-bit target) and weaker
// lights keep their ratio. Zero when every light is black.
static inline void godray_tint(const st_light_desc *lights, int num_lights, int k, float out[3]) {
    float mx = 0;
    for (int i = 0; i < num_lights; i++)
        for (int c = 0; c < 3; c++)
            if (lights[i].intensity[c] > mx) mx = lights[i].intensity[c];
    for (int c = 0; c < 3; c++) {
        float v = lights[k].intensity[c];
        out[c] = mx > 0 && v > 0 ? v / mx : 0.0f;
    }
}

// Shafts need something to scatter: a medium with sigma_s > 0 in some channel.
static inline bool godray_medium_active(const st_scene *s) {
    return s->medium.present && (s->medium.sigma_s[0] > 0 || s->medium.sigma_s[1] > 0 || s->medium.sigma_s[2] > 0);
}

#endif
