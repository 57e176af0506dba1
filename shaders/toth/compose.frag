// toth's last pass: adds the in-scattered light at full resolution to what
// the camera sees (hdr_in, already L_surface e^(-sigma_t s): the regular pass
// owns the view ray's extinction, docs/physics.md). A march at reduced
// resolution is upsampled depth-aware (toth/upsample.glsl). With
// sampling=equiangular the march holds each light's visible fraction: the
// smooth unshadowed integral is evaluated here for every full-resolution
// pixel (the airlight table, or Gauss-Legendre nodes), so upsampling and
// interleaving touch only the visibility and never blur the glow of a light
// in view. Pixels whose taps disagree were marched by the edges pass; their
// fractions are read here (no march code in this pass: llvmpipe would run it
// masked for every pixel).
#include "common/uniforms.glsl"
#include "toth/common.glsl"
#include "toth/equiangular.glsl"
// compose=table: toth.c compiles the parameter in as TOTH_COMPOSE (0: table).
#if defined(TOTH_COMPOSE) && TOTH_COMPOSE == 0
#define TOTH_AIRLIGHT 1
#endif
#ifdef TOTH_AIRLIGHT
#include "toth/airlight.glsl" // compose=table
#else
#define toth_unshadowed toth_eq_unshadowed // compose=quadrature
#endif
#include "toth/upsample.glsl"
#ifdef TOTH_REUSE
#include "toth/reuse.glsl" // jittered frames of a still, reuse=on
#endif
#include "toth/glow.glsl" // a light in view under the box filter: the pixel's mean
uniform sampler2D st_hdr_in;
uniform int toth_has_inscatter;
uniform int toth_sampling; // 0 uniform, 1 equiangular
uniform int toth_nodes;    // Gauss-Legendre nodes of the unshadowed integral
layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 g = texelFetch(st_gbuffer, p, 0);
    vec3 sigma_t = st_sigma_s + st_sigma_a;
    vec3 L = texelFetch(st_hdr_in, p, 0).rgb;
    // One upsampling for both modes: llvmpipe runs both sides of a branch on
    // a uniform, so a call in each side would be paid twice.
    float spread = 0.0;
#ifdef TOTH_REUSE
    // A jittered frame of a still (reuse=on, equiangular): the first frame's
    // fractions at this ray's position, nothing marched or upsampled.
    vec4 up = toth_first_fraction(p, g);
#else
    vec4 up = toth_has_inscatter != 0 ? toth_upsample(p, g, spread) : vec4(0.0);
#endif
    if (toth_has_inscatter != 0 && toth_sampling == 1) {
        vec4 frac = up;
        float s = toth_ray_length(g, p);
#ifndef TOTH_REUSE
        // Where the taps disagree (a shaft's edge, a silhouette) the
        // interpolated fraction is a guess: the edges pass's own ray.
        frac = toth_refined(p, up, spread);
#endif
        // One light: its fraction per colour channel (toth_rgb_fraction).
        bool rgb = st_num_lights == 1;
        for (int l = 0; l < st_num_lights; l++)
            L += (rgb ? frac.xyz : vec3(frac[min(l, 3)])) *
                 toth_glow_unshadowed(p, s, l, toth_nodes, st_sigma_s, sigma_t);
    } else if (toth_has_inscatter != 0) {
        L += up.rgb;
    }
    // Never write NaN or Inf: absurd inputs (sigma near float max) saturate.
    for (int c = 0; c < 3; c++) {
        if (isnan(L[c])) L[c] = 0.0;
        L[c] = clamp(L[c], 0.0, 3.0e38);
    }
    o_radiance = vec4(L, 1.0);
}
