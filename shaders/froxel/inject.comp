// froxel pass 1: per froxel, the medium's density and the in-scattered
// radiance per metre toward the camera at the froxel's sample point
// (docs/physics.md): density sigma_s sum over the lights of
// phase(theta) E V e^(-optical depth to the light), E = I/d^2 (point),
// I falloff/d^2 (spot), the irradiance (sun), V from shadow_map. The sample
// lies on the column's centre ray at froxel_offset of the slice's depth.
#include "common/uniforms.glsl"
#include "shadow_map/visibility.glsl"
#include "common/lighting.glsl"
#include "froxel/grid.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba32f, binding = 0) uniform writeonly image2DArray froxel_inject_img;

// temporal: the previous frame's grid (source, mean density), reprojected
// through the previous frame's matrices and blended in with weight
// froxel_history (Hillaire 2015's history; trilinear between its froxels'
// centres, the current value alone where x was outside that grid). Read as
// an image: llvmpipe's compiler crashes on a sampled array here.
uniform int froxel_temporal;
uniform float froxel_history;
uniform mat4 froxel_prev_view_proj, froxel_prev_view;
layout(rgba32f, binding = 2) uniform readonly image2DArray froxel_history_img;

vec4 froxel_history_at(ivec3 c) {
    return imageLoad(froxel_history_img, clamp(c, ivec3(0), froxel_grid - 1));
}

vec4 froxel_reproject(vec3 x, vec4 cur) {
    if (froxel_temporal == 0) return cur;
    vec4 p = froxel_prev_view_proj * vec4(x, 1.0);
    if (!(p.w > 0.0)) return cur;
    vec2 ndc = p.xy / p.w;
    if (any(greaterThan(abs(ndc), vec2(1.0)))) return cur;
    float u = froxel_slice(-(froxel_prev_view * vec4(x, 1.0)).z);
    if (!(u >= 0.0 && u <= 1.0)) return cur;
    // Continuous froxel coordinates relative to the centres.
    vec3 g = vec3((ndc * 0.5 + 0.5) * vec2(froxel_grid.xy), u * float(froxel_grid.z)) - 0.5;
    ivec3 i = ivec3(floor(g));
    vec3 f = g - vec3(i);
    vec4 h = vec4(0.0);
    for (int k = 0; k < 8; k++) {
        ivec3 o = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        vec3 w = mix(1.0 - f, f, vec3(o));
        h += w.x * w.y * w.z * froxel_history_at(i + o);
    }
    return mix(cur, h, froxel_history);
}

// What positioned light l scatters toward the camera per unit sigma_s,
// averaged over the slice's stretch [t0, t1] of the column's ray, before
// visibility and the light's transmittance: I times the mean of
// f(t) phase(t) / d(t)^2 (f the spot's falloff). A point sample at the
// froxel's centre would miss the 1/d^2 peak of a light near the ray, or
// multiply it by the whole slice. With h the ray's distance from the light
// and a, b the ends relative to the foot point, the mean of 1/(h^2 + t^2) is
// (atan(b/h) - atan(a/h)) / (h (b - a)) (docs/physics.md's closed form);
// f and the phase function are averaged with that weight at 4 Gauss nodes.
// h^2 gets the froxel's width^2 / 12 (the mean square offset across it: the
// column stands for all of its pixels) and R^2, the light's near field
// (grid.glsl), whose rest the compose pass adds per pixel.
const float FROXEL_GL4_X[2] = float[2](0.3399810436, 0.8611363116);
const float FROXEL_GL4_W[2] = float[2](0.6521451549, 0.3478548451);

vec3 froxel_positioned(int l, vec3 dir, float t0, float t1, float width) {
    vec3 v = st_light_pos[l] - st_cam_pos;
    float foot = dot(v, dir);
    vec3 across = v - foot * dir;
    float R = froxel_near_radius(l);
    float h2 = dot(across, across) + width * width / 12.0 + R * R;
    float h = sqrt(max(h2, 1e-20));
    float a = t0 - foot, b = t1 - foot;
    // With the foot point outside [a, b] the difference of the two angles is
    // taken as one atan, which does not cancel far from the light.
    float q = h2 + a * b;
    float ang = q > 0.0 ? atan(h * (b - a), q) : atan(b / h) - atan(a / h);
    float mean = ang / (h * max(b - a, 1e-20));
    float num = 0.0, den = 0.0;
    for (int k = 0; k < 4; k++) {
        float t = 0.5 * (a + b) + 0.5 * (b - a) * (k < 2 ? -FROXEL_GL4_X[1 - k] : FROXEL_GL4_X[k - 2]);
        float w = FROXEL_GL4_W[k < 2 ? 1 - k : k - 2] / (h2 + t * t);
        vec3 to_light = normalize(across - t * dir); // from the ray point at foot + t
        float f = 1.0;
        if (ST_LIGHT_IS(l, ST_LIGHT_SPOT)) {
            float s = clamp(-dot(to_light, st_light_dir[l]) * st_light_shape[l].x + st_light_shape[l].y, 0.0, 1.0);
            f = s * s;
        }
        num += w * f * st_phase(st_phase_kind, dot(to_light, dir), st_phase_g);
        den += w;
    }
    return st_light_intensity[l] * (mean * num / max(den, 1e-30));
}

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(id, froxel_grid))) return;
    vec3 dir = froxel_column_dir(id.xy);
    float c = froxel_cos(dir);
    float n = float(froxel_grid.z);
    float z0 = froxel_depth(float(id.z) / n), z1 = froxel_depth(float(id.z + 1) / n);
    float t0 = z0 / c, t1 = z1 / c;
    vec3 x = st_cam_pos + dir * mix(t0, t1, froxel_offset);
    // The froxel's width across the ray at the sample (its rows span the
    // view's height at that depth).
    float width = 2.0 * mix(z0, z1, froxel_offset) * tan(0.5 * st_fov_y) / float(froxel_grid.y);
    // The medium's density (common/medium.glsl): at the sample for the source,
    // and the slice's mean (its optical depth over its length: exact for
    // height fog and grids) for the extinction the integration applies.
    float dens = st_density(x);
#if ST_DENSITY_VARIES
    float mean_dens = st_optical_depth(st_cam_pos, dir, t0, t1) / max(t1 - t0, 1e-30);
#else
    float mean_dens = 1.0;
#endif
    vec3 S = vec3(0.0);
    if (dens > 0.0) {
        for (int l = 0; l < st_num_lights; l++) {
            vec3 G, to_light;
            float path;
            if (ST_LIGHT_IS(l, ST_LIGHT_DIRECTIONAL)) {
                to_light = -st_light_dir[l];
                path = max(0.0, st_light_shape[l].z - dot(x, to_light));
                G = st_light_intensity[l] * st_phase(st_phase_kind, dot(to_light, dir), st_phase_g);
            } else {
                to_light = st_light_pos[l] - x;
                path = length(to_light);
                to_light /= max(path, 1e-30);
                G = froxel_positioned(l, dir, t0, t1, width);
            }
            if (all(equal(G, vec3(0.0)))) continue;
            float vis = st_visibility_point(l, x);
            // Extinction first: a large optical depth underflows to 0 instead
            // of forming inf * 0.
            if (vis > 0.0) S += vis * (st_light_transmittance(x, to_light, path) * G);
        }
    }
    imageStore(froxel_inject_img, id, froxel_reproject(x, vec4(dens * st_sigma_s * S, mean_dens)));
}
