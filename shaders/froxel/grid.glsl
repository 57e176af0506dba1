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
uniform float froxel_offset;   // where in its slice a froxel is sampled, [0, 1)

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
    return froxel_near_scale * max(max(width, len), 1e-4);
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

// The ray of column c: through the centre of its cell of the screen.
vec3 froxel_column_dir(ivec2 c) { return froxel_ndc_dir((vec2(c) + 0.5) / vec2(froxel_grid.xy) * 2.0 - 1.0); }

// The cosine between a ray and the view axis: view depth z lies t = z / cos
// along the ray.
float froxel_cos(vec3 dir) { return max(dot(dir, froxel_axis()), 1e-3); }
#endif
