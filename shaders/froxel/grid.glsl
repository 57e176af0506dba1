// froxel: the grid. Column (x, y) is the view ray through the centre of its
// share of the screen; slice k spans the view depths [z(k / N), z((k + 1) / N)]
// with z(u) = far (e^(e u) - 1) / (e^e - 1) (e the exponent; linear at 0), so
// the grid starts at the camera, where the in-scattering integral starts.
#ifndef FROXEL_GRID_GLSL
#define FROXEL_GRID_GLSL
#include "common/uniforms.glsl"

uniform ivec3 froxel_grid;     // columns, rows, slices
uniform float froxel_far;      // view depth of the last slice's end
uniform float froxel_exponent; // depth distribution
uniform float froxel_offset;   // temporal: where in its slice a froxel is sampled, [0, 1)
uniform int froxel_reuse;      // 1: a box still's jittered frame reads its first frame's grid
uniform int st_filter_sample;  // the world's: this frame's index in the box filter's mean

// Where in its slice this frame samples its froxels, [0, 1): the midpoint,
// or with temporal the frame's offset. The columns pass through their
// cells' centres (of the frame's projection).
float froxel_slice_offset() { return froxel_offset; }

// View depth of the slice coordinate u in [0, 1].
float froxel_depth(float u) {
    float e = froxel_exponent;
    if (e < 1e-4) return froxel_far * u;
    return froxel_far * (exp(e * u) - 1.0) / (exp(e) - 1.0);
}

// Its inverse: the slice coordinate of view depth z (unclamped).
float froxel_slice(float z) {
    float e = froxel_exponent;
    if (e < 1e-4) return z / froxel_far;
    return log(1.0 + max(z, 0.0) / froxel_far * (exp(e) - 1.0)) / e;
}

uniform int froxel_near_field;    // 1: the near field of positioned lights per pixel
uniform float froxel_near_scale; // its radius in froxels

// The radius R of light l's near field: the larger of a froxel's width and
// its slice's length at the light's view depth. The kernel 1/d^2 is split
// into 1/(d^2 + R^2), smooth at the froxels' scale, which the grid carries,
// and the rest, R^2 / (d^2 (d^2 + R^2)), which is concentrated within a few
// R of the light and is integrated along each pixel's own ray (compose).
// 0 without the near field.
float froxel_near_radius(int l) {
    if (froxel_near_field == 0) return 0.0;
    vec3 axis = -normalize(vec3(st_view[0][2], st_view[1][2], st_view[2][2]));
    float z = clamp(dot(st_light_pos[l] - st_cam_pos, axis), 0.0, froxel_far);
    float width = 2.0 * z * tan(0.5 * st_fov_y) / float(froxel_grid.y);
    float n = float(froxel_grid.z), u = froxel_slice(z);
    float u1 = min(u + 1.0 / n, 1.0);
    float len = froxel_depth(u1) - froxel_depth(u1 - 1.0 / n);
    // Tiles wider than 4 pixels (512 x 512 at the defaults: 8) widen it in
    // proportion: the image then resolves what the grid blurs over a froxel,
    // a spot's cone next to its apex above all (spot_fog at 512 x 512, box
    // still against the reference, the 10 pixels of largest error left out:
    // NRMSE 0.096 at 2 froxels, 0.056 at 4; outside the light's 4-px disk
    // 0.048); smaller tiles keep near_radius as it is.
    float tile = st_resolution.y / float(froxel_grid.y);
    return froxel_near_scale * max(1.0, 0.25 * tile) * max(max(width, len), 1e-4);
}

// The stretch [lo, hi] of the ray origin + t dir that lies inside spot l's
// outer cone, clipped to the given [lo, hi]; false if none. Where the ray
// passes the light within a few cone widths the falloff rises and falls
// within a small part of the ray, which quadrature over the whole ray (the
// near field, the slice's nodes) would miss: the nodes go to this stretch.
bool froxel_spot_range(int l, vec3 origin, vec3 dir, inout float lo, inout float hi) {
    vec3 a = st_light_dir[l], w = origin - st_light_pos[l];
    float co = -st_light_shape[l].y / st_light_shape[l].x, c2 = co * co;
    float da = dot(dir, a), wa = dot(w, a);
    // (v.a)^2 - cos^2 |v|^2 = A t^2 + B t + C along v = w + t dir; inside
    // the forward cone where it is >= 0 and v.a >= 0.
    float A = da * da - c2, B = 2.0 * (wa * da - c2 * dot(w, dir)), C = wa * wa - c2 * dot(w, w);
    float disc = B * B - 4.0 * A * C;
    if (co <= 0.0 || abs(A) < 1e-7 || disc < 0.0) return true; // wide or degenerate: keep all
    float q = -0.5 * (B + sign(B) * sqrt(disc));
    float r1 = q / A, r2 = abs(q) > 0.0 ? C / q : r1;
    if (r1 > r2) { float t = r1; r1 = r2; r2 = t; }
    float in0, in1;
    if (A < 0.0) { // one finite stretch, on one nappe
        if (wa + 0.5 * (r1 + r2) * da < 0.0) return false;
        in0 = r1, in1 = r2;
    } else if (wa + (r2 + 1.0) * da >= 0.0) { // the forward nappe holds [r2, inf)
        in0 = r2, in1 = 1e30;
    } else {
        in0 = -1e30, in1 = r1;
    }
    lo = max(lo, in0), hi = min(hi, in1);
    return hi > lo;
}

// The camera's unit view axis (world space).
vec3 froxel_axis() { return -normalize(vec3(st_view[0][2], st_view[1][2], st_view[2][2])); }

// Unit direction of the view ray through NDC point ndc (the frame's
// jittered projection, as the regular pass draws it).
vec3 froxel_ndc_dir(vec2 ndc) {
    vec4 a = st_inv_view_proj * vec4(ndc, -1.0, 1.0);
    vec4 b = st_inv_view_proj * vec4(ndc, 1.0, 1.0);
    return normalize(b.xyz / b.w - a.xyz / a.w);
}

// The ray of column c: through its cell's centre on the screen.
vec3 froxel_column_dir(ivec2 c) {
    vec2 cell = vec2(c) + 0.5;
    return froxel_ndc_dir(cell / vec2(froxel_grid.xy) * 2.0 - 1.0);
}

// The cosine between a ray and the view axis: view depth z lies t = z / cos
// along the ray.
float froxel_cos(vec3 dir) { return max(dot(dir, froxel_axis()), 1e-3); }
#endif
