// toth: the visible fraction of each light's in-scattering along a view ray,
// with the march samples placed equi-angularly (see equiangular.glsl). Light
// l's share of the unshadowed integral is weighted by the smooth angular
// integrand, so the fraction sum(w V) / sum(w) is exact for a fully lit or
// fully shadowed ray at any sample count and the samples crowd where the
// light contributes most. Lights 0..2 get a channel each; lights 3.. share
// the fourth (exact when they see the same occluders).
#ifndef TOTH_VISIBILITY_GLSL
#define TOTH_VISIBILITY_GLSL
#include "toth/equiangular.glsl"
#include "shadow_map/visibility.glsl"

// Steps first, first + stride, ... < n of n equal steps in theta, each
// sampled at fraction u in [0, 1). Returns the fraction per channel (1 where
// a light adds nothing, so the full-resolution product stays exact).
vec4 toth_visible_fraction(vec3 o, vec3 dir, float s, int n, int first, int stride, float u, vec3 sigma_t) {
    n = max(n, 1);
    stride = max(stride, 1);
    // One weight for all channels: visibility is grey, and the channels'
    // extinctions differ little.
    vec3 grey = vec3((sigma_t.x + sigma_t.y + sigma_t.z) / 3.0);
    vec4 num = vec4(0.0), den = vec4(0.0);
    for (int l = 0; l < st_num_lights; l++) {
        toth_eq e = toth_eq_frame(o, dir, s, st_light_pos[l]);
        if (!(e.len > 0.0)) continue;
        float step = e.len / float(n);
        int c = min(l, 3);
        for (int i = first; i < n; i += stride) {
            float delta = (float(i) + u) * step, t, d;
            toth_eq_point(e, delta, t, d);
            float w = toth_eq_integrand(e, delta, grey).x;
            if (!(w > 0.0)) continue;
            num[c] += w * st_visibility_point(l, o + t * dir);
            den[c] += w;
        }
    }
    vec4 f;
    for (int c = 0; c < 4; c++) f[c] = den[c] > 0.0 ? clamp(num[c] / den[c], 0.0, 1.0) : 1.0;
    return f;
}
#endif
