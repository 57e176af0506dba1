// toth: the glow of a point or spot light in view under the box filter
// (compose pass). The unshadowed in-scattering grows like 1/h with the view
// ray's distance h from the light, so near the light's projection its mean
// over the pixel's square has a huge variance under the box filter's one
// jittered sample per frame: on scenes/cornell.json at 256^2 three pixels at
// the glow held 44% of the accumulated still's remaining error, and the
// stopping rule waited for them. There, compose integrates the unshadowed
// term over the pixel's footprint itself: toth_glow x toth_glow sub-rays, one
// in each cell of the pixel's square, at the place in its cell that the
// frame's jitter gives (so every frame is a stratified estimate of the
// pixel's own square), and each frame already returns nearly the pixel's
// mean. The visible fraction stays the one of the
// frame's jittered sample (about 1 that close to a light in view). With the
// point filter (st_pixel_jitter.z = 0), toth_glow = 1 or away from the
// lights every pixel keeps its one centre ray, bit-identical.
#ifndef TOTH_GLOW_GLSL
#define TOTH_GLOW_GLSL
#include "common/uniforms.glsl"
#include "toth/common.glsl"

uniform vec3 st_pixel_jitter; // the world's: this frame's sample offset, z = 1 under the box filter
uniform int toth_glow;        // sub-rays per axis near a light in view (1 = off)
uniform float toth_glow_radius; // ... within this many pixels of its projection

// Sub-rays per axis for light l at full-resolution pixel p: toth_glow where
// the pixel's ray passes the light (in front of the camera) within
// toth_glow_radius pixels at the light's distance, else 1.
int toth_glow_rays(ivec2 p, int l) {
    if (st_pixel_jitter.z == 0.0 || toth_glow <= 1 || !ST_LIGHT_POSITIONED(l)) return 1;
    vec3 rel = st_light_pos[l] - st_cam_pos;
    vec3 dir = toth_view_dir(p);
    float t = dot(rel, dir);
    float pixel = 2.0 * tan(0.5 * st_fov_y) / st_resolution.y;
    return t > 0.0 && length(cross(rel, dir)) < toth_glow_radius * pixel * t ? toth_glow : 1;
}

// An antiderivative of 1/r, r = |(x, y)|, in x and y (d^2/dxdy of
// x ln(y + r) + y ln(x + r); the ln|x| and ln|y| parts cancel over a
// rectangle's corners), finite on the axes.
float toth_glow_prim(float x, float y) {
    return (x != 0.0 ? x * asinh(y / abs(x)) : 0.0) + (y != 0.0 ? y * asinh(x / abs(y)) : 0.0);
}

// The mean of 1/r over the square of side 2 a centred d pixels from the
// light's image, times the distance (at least r_min, the bound
// toth_eq_hmin puts on h) of the sub-ray at d + u inside it: the factor
// that turns the sub-ray's value F / h into the cell's mean F <1/h>, F (the
// angular integral, smooth in h) taken at the sub-ray. Within 2 pixels of
// the light, where 1/r varies across a cell; beyond, the factor is 1 within
// (a / r)^2 / 6 (and the corners' sum would lose digits).
float toth_glow_cell(vec2 d, vec2 u, float a, float r_min) {
    if (length(d) >= 2.0) return 1.0;
    vec2 lo = d - a, hi = d + a;
    float I = toth_glow_prim(hi.x, hi.y) - toth_glow_prim(lo.x, hi.y) - toth_glow_prim(hi.x, lo.y) +
              toth_glow_prim(lo.x, lo.y);
    return max(length(d + u), r_min) * I / (4.0 * a * a);
}

// The unshadowed in-scattering of light l for pixel p (ray length s): the
// centre ray's, or near the light the mean of n x n sub-rays over the
// pixel's square, each standing for its cell: the 1/h singularity is
// integrated over the cell in closed form (toth_glow_cell), so the cell
// that holds the light adds no noise and no bias from the bound on h. One
// call site of toth_unshadowed (llvmpipe pays for every call written,
// taken or not).
vec3 toth_glow_unshadowed(ivec2 p, float s, int l, int nodes, vec3 sigma_s, vec3 sigma_t) {
    int n = toth_glow_rays(p, l);
    vec3 sum = vec3(0.0);
    // The light's image in this frame's window coordinates (in front of the
    // camera wherever n > 1).
    vec4 c = st_view_proj * vec4(st_light_pos[l], 1.0);
    vec2 q = (c.xy / max(c.w, 1e-30) * 0.5 + 0.5) * st_resolution;
    toth_eq_hmin_pixels = 0.25 / float(n);
    // The n x n cells of the pixel's square; each sub-ray sits at the same
    // place in its cell, the frame's jitter scaled to the cell (n = 1: the
    // frame's own sample). Window coordinates of this (jittered) frame: the
    // pixel's square is centred st_pixel_jitter.xy off its sample.
    float a = 0.5 / float(n);
    vec2 u = n > 1 ? (fract(st_pixel_jitter.xy * float(n) + 0.5) - 0.5) / float(n) : vec2(0.0);
    vec2 centre = vec2(p) + 0.5 - (n > 1 ? st_pixel_jitter.xy : vec2(0.0));
    for (int k = 0; k < n * n; k++) {
        vec2 cell = centre + (vec2(k % n, k / n) + 0.5) / float(n) - 0.5;
        vec2 x = n > 1 ? cell + u : vec2(p) + 0.5;
        vec3 dir = toth_ndc_dir(x / st_resolution * 2.0 - 1.0);
        float w = n > 1 ? toth_glow_cell(cell - q, u, a, toth_eq_hmin_pixels) : 1.0;
        sum += w * toth_unshadowed(st_cam_pos, dir, s, l, nodes, sigma_s, sigma_t);
    }
    toth_eq_hmin_pixels = 0.25;
    return sum / float(n * n);
}
#endif
