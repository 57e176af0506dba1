// froxel pass 1: per froxel, the medium's density and the in-scattered
// radiance per metre toward the camera at the froxel's sample point
// (docs/physics.md): density sigma_s sum over the lights of
// phase(theta) E V e^(-optical depth to the light), E = I/d^2 (point),
// I falloff/d^2 (spot), the irradiance (sun), V from shadow_map. The sample
// lies on the column's ray at the offset of grid.glsl's froxel_slice_offset;
// with taps (below) the source is the mean over 4 points of the froxel.
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

// The history holds what the froxels scattered toward the previous frame's
// camera: `to_cur` (per channel) turns it toward this one, the ratio of this
// frame's source to the same lights seen with the phase function from the
// previous camera (exact for one light; without it a moved camera sees the
// old pose's phase function for the blend's frames, a smear).
uniform vec3 froxel_prev_cam;

vec4 froxel_reproject(vec3 x, vec4 cur, vec3 to_cur) {
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
    h.rgb *= to_cur;
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

// The froxel's taps (FROXEL_TAPS 1, `taps=footprint`): the Gauss nodes of
// the slice's stretch of the column's ray (those froxel_positioned weights
// the light's falloff at), each moved across the ray to a point of a rotated
// grid over the froxel's cell. The source takes the density, the shadow_map
// visibility and the light's transmittance at each, so it is the froxel's
// mean, not its centre's: a shadow thinner than a froxel (a mullion's)
// otherwise turns whole froxels on or off, and in a dense cloud the light's
// transmittance falls by much within one slice.
// FROXEL_TAPS is the parameter's index: 0 center (one point), 1 footprint.
#ifndef FROXEL_TAPS
#define FROXEL_TAPS 0
#endif
// FROXEL_TAP_SPREAD 0 keeps the taps on the column's ray (a box still's
// kept grid: its frames' sub-pixel offsets already spread it over the pixel).
#ifndef FROXEL_TAP_SPREAD
#define FROXEL_TAP_SPREAD 1.0
#endif
const vec2 FROXEL_TAP_XY[4] = vec2[4](vec2(-0.375, -0.125), vec2(0.125, -0.375),
                                      vec2(0.375, 0.125), vec2(-0.125, 0.375));

// Node k of [a, b] and its weight (sum 1): Gauss-Legendre, 4 points, or
// with FROXEL_MIDPOINTS n the midpoints of n equal parts (a box still's
// kept grid: a shadow's edge inside a slice weighs by the stretch it cuts
// off, where 4 Gauss nodes round it to their weights).
#ifndef FROXEL_MIDPOINTS
#define FROXEL_MIDPOINTS 0
#endif
const int FROXEL_NODES = FROXEL_MIDPOINTS > 0 ? FROXEL_MIDPOINTS : 4;
float froxel_node(float a, float b, int k) {
    if (FROXEL_MIDPOINTS > 0) return a + (b - a) * (float(k) + 0.5) / float(FROXEL_MIDPOINTS);
    return 0.5 * (a + b) + 0.5 * (b - a) * (k < 2 ? -FROXEL_GL4_X[1 - k] : FROXEL_GL4_X[k - 2]);
}
float froxel_node_w(int k) {
    if (FROXEL_MIDPOINTS > 0) return 1.0 / float(FROXEL_MIDPOINTS);
    return 0.5 * FROXEL_GL4_W[k < 2 ? 1 - k : k - 2];
}

vec3 froxel_tap_point(vec3 dir, float t, float c, int k) {
    vec3 right = vec3(st_view[0][0], st_view[1][0], st_view[2][0]);
    vec3 up = vec3(st_view[0][1], st_view[1][1], st_view[2][1]);
    float sy = 2.0 * tan(0.5 * st_fov_y) / float(froxel_grid.y);
    float sx = sy * (st_resolution.x / st_resolution.y) * float(froxel_grid.y) / float(froxel_grid.x);
    vec2 o = FROXEL_TAP_SPREAD * FROXEL_TAP_XY[k & 3] * vec2(sx, sy) * (t * c);
    return st_cam_pos + t * dir + o.x * right + o.y * up;
}

// The medium's share of light l's in-scattering at p: density, shadow_map
// visibility and the light's transmittance (extinction first: a large
// optical depth underflows to 0 instead of forming inf * 0).
vec3 froxel_medium_at(int l, vec3 p) {
    float dens = st_density(p);
    if (!(dens > 0.0)) return vec3(0.0);
    vec3 to_light;
    float path;
    if (ST_LIGHT_IS(l, ST_LIGHT_DIRECTIONAL)) {
        to_light = -st_light_dir[l];
        path = max(0.0, st_light_shape[l].z - dot(p, to_light));
    } else {
        to_light = st_light_pos[l] - p;
        path = length(to_light);
        to_light /= max(path, 1e-30);
    }
    float vis = st_visibility_point(l, p);
    return vis > 0.0 ? dens * vis * st_light_transmittance(p, to_light, path) : vec3(0.0);
}

// Positioned light l over the slice's stretch [t0, t1] of the column's ray:
// I times the mean of f phase / d^2, and with taps the medium at each node
// (froxel_medium_at) inside the mean.
vec3 froxel_positioned(int l, vec3 dir, float t0, float t1, float width, float c) {
    vec3 v = st_light_pos[l] - st_cam_pos;
    float foot = dot(v, dir);
    vec3 across = v - foot * dir;
    float R = froxel_near_radius(l);
    float h2 = dot(across, across) + width * width / 12.0 + R * R;
    float h = sqrt(max(h2, 1e-20));
    // A spot: the mean over the stretch inside its cone, times its share of
    // the slice (the nodes then resolve the falloff near the apex).
    float lo = t0, hi = t1;
    if (ST_LIGHT_IS(l, ST_LIGHT_SPOT) && !froxel_spot_range(l, st_cam_pos, dir, lo, hi)) return vec3(0.0);
    float share = (hi - lo) / max(t1 - t0, 1e-20);
    float a = lo - foot, b = hi - foot;
    // With the foot point outside [a, b] the difference of the two angles is
    // taken as one atan, which does not cancel far from the light.
    float q = h2 + a * b;
    float ang = q > 0.0 ? atan(h * (b - a), q) : atan(b / h) - atan(a / h);
    float mean = ang / (h * max(b - a, 1e-20));
    vec3 num = vec3(0.0);
    float den = 0.0;
    for (int k = 0; k < FROXEL_NODES; k++) {
        float t = froxel_node(a, b, k);
        float w = froxel_node_w(k) / (h2 + t * t);
        vec3 to_light = normalize(across - t * dir); // from the ray point at foot + t
        float f = 1.0;
        if (ST_LIGHT_IS(l, ST_LIGHT_SPOT)) {
            float s = clamp(-dot(to_light, st_light_dir[l]) * st_light_shape[l].x + st_light_shape[l].y, 0.0, 1.0);
            f = s * s;
        }
        float g = w * f * st_phase(st_phase_kind, dot(to_light, dir), st_phase_g);
        if (FROXEL_TAPS == 0)
            num += vec3(g);
        else if (g > 0.0)
            num += g * froxel_medium_at(l, froxel_tap_point(dir, foot + t, c, k));
        den += w;
    }
    return st_light_intensity[l] * (share * mean * num / max(den, 1e-30));
}

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(id, froxel_grid))) return;
    vec3 dir = froxel_column_dir(id.xy);
    float c = froxel_cos(dir);
    float n = float(froxel_grid.z);
    float z0 = froxel_depth(float(id.z) / n), z1 = froxel_depth(float(id.z + 1) / n);
    float t0 = z0 / c, t1 = z1 / c;
    float at = froxel_slice_offset();
    vec3 x = st_cam_pos + dir * mix(t0, t1, at);
    // The froxel's width across the ray at the sample (its rows span the
    // view's height at that depth).
    float width = 2.0 * mix(z0, z1, at) * tan(0.5 * st_fov_y) / float(froxel_grid.y);
    // The medium's density (common/medium.glsl): at the sample or the taps
    // for the source (froxel_medium_at), and the slice's mean (its optical
    // depth over its length: exact for height fog and grids) for the
    // extinction the integration applies.
#if ST_DENSITY_VARIES
    float mean_dens = st_optical_depth(st_cam_pos, dir, t0, t1) / max(t1 - t0, 1e-30);
#else
    float mean_dens = 1.0;
#endif
    vec3 S = vec3(0.0), S_prev = vec3(0.0); // S_prev: phase from the previous camera
    vec3 from_prev = normalize(x - froxel_prev_cam);
    for (int l = 0; l < st_num_lights; l++) {
        vec3 S_l = S;
        if (ST_LIGHT_IS(l, ST_LIGHT_DIRECTIONAL)) {
            vec3 G = st_light_intensity[l] * st_phase(st_phase_kind, dot(-st_light_dir[l], dir), st_phase_g);
            if (FROXEL_TAPS == 0) {
                S += G * froxel_medium_at(l, x);
            } else {
                for (int k = 0; k < FROXEL_NODES; k++)
                    S += froxel_node_w(k) * G * froxel_medium_at(l, froxel_tap_point(dir, froxel_node(t0, t1, k), c, k));
            }
        } else {
            vec3 G = froxel_positioned(l, dir, t0, t1, width, c);
            if (FROXEL_TAPS == 0 && any(greaterThan(G, vec3(0.0)))) G *= froxel_medium_at(l, x);
            S += G;
        }
        if (froxel_temporal != 0) {
            vec3 L = ST_LIGHT_IS(l, ST_LIGHT_DIRECTIONAL) ? -st_light_dir[l] : normalize(st_light_pos[l] - x);
            float now = st_phase(st_phase_kind, dot(L, dir), st_phase_g);
            S_prev += (S - S_l) * (st_phase(st_phase_kind, dot(L, from_prev), st_phase_g) / max(now, 1e-30));
        }
    }
    vec3 to_cur = vec3(1.0);
    for (int k = 0; k < 3; k++)
        if (S_prev[k] > 0.0) to_cur[k] = S[k] / S_prev[k];
    // temporal: the history is read where this frame's value stands, the
    // sample, or with taps the froxel's centre (the taps' mean is its value).
    vec3 at_x = FROXEL_TAPS == 0 ? x : st_cam_pos + dir * (0.5 * (t0 + t1));
    imageStore(froxel_inject_img, id, froxel_reproject(at_x, vec4(st_sigma_s * S, mean_dens), to_cur));
}
