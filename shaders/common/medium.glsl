// Extinction on every path (docs/physics.md): with a medium, light travelling
// from a light to a surface or scattering point, from a bounce's sender to
// its receiver, and from what the camera sees to the camera, is attenuated
// by e^(-sigma_t tau), tau the optical depth per unit sigma_t: the path's
// length in a homogeneous medium, the density's integral along it where the
// density varies (medium.density). C: st_medium_sigma_t, st_transmittance,
// st_density_at, st_density_integral. The view ray's share is applied once,
// by the regular pass (regular.frag, background.frag); volumetric modules
// only add light.
//
// The density API (stable: volumetric modules build on it). Rays are
// o + t w with w a unit vector.
//   ST_DENSITY                 compile-time: 0 homogeneous (density 1), 1
//                              height fog, 2 grid. The world appends it to the
//                              light defines (st_world_light_defines) of a
//                              scene whose density varies; without it
//                              (homogeneous scenes) the code below compiles
//                              to the homogeneous forms, unchanged bit for
//                              bit.
//   ST_DENSITY_VARIES          ST_DENSITY != 0, for #if.
//   float st_density(vec3 x)   d(x): 1, e^(-k (y - y0)), or the grid's
//                              trilinear value between voxel centres (0
//                              outside its block), as C's st_density_at.
//   float st_optical_depth(vec3 o, vec3 w, float t0, float t1)
//                              tau = integral_t0^t1 d(o + t w) dt: t1 - t0;
//                              height fog in closed form; a grid exactly, by
//                              a DDA over its cells with 2-point
//                              Gauss-Legendre per piece (as C).
//   vec3 st_depth_transmittance(float tau)
//                              e^(-sigma_t tau) per channel (1 without a
//                              medium).
//   vec3 st_segment_transmittance(vec3 o, vec3 w, float t0, float t1)
//                              the two above along a segment.
//   vec3 st_light_transmittance(vec3 x, vec3 to_light, float path)
//                              a light path from x toward a light (unit
//                              to_light) over `path` metres (the distance
//                              to a point or spot light, the path to a
//                              directional light's entry plane); the
//                              homogeneous st_path_transmittance(path) when
//                              ST_DENSITY is 0.
//   vec3 st_view_ray_transmittance(vec3 w, float s)
//                              the view ray from the camera along unit w to
//                              s metres; st_view_transmittance(s) when
//                              ST_DENSITY is 0.
//   vec3 st_path_transmittance(float d), st_view_transmittance(float s)
//                              the homogeneous forms (length only).
// Bounds: d and tau are clamped to ST_DENSITY_MAX (1e20) so that absurd
// inputs (falloff 1e4 far below the base) saturate instead of producing
// inf * 0 = NaN in products like sigma_s d e^(-sigma_t tau).
#ifndef ST_MEDIUM_GLSL
#define ST_MEDIUM_GLSL
#include "common/uniforms.glsl"
#include "common/physics.glsl"

#ifndef ST_DENSITY
#define ST_DENSITY 0
#endif
#define ST_DENSITY_VARIES (ST_DENSITY != 0)
const float ST_DENSITY_MAX = 1e20;

vec3 st_medium_sigma_t() { return st_has_medium != 0 ? st_sigma_s + st_sigma_a : vec3(0.0); }

// Transmittance of a light path of length d through a homogeneous medium.
vec3 st_path_transmittance(float d) { return st_transmittance(st_medium_sigma_t(), d); }

// Transmittance of the view ray from the camera to a point s metres away
// (homogeneous medium).
vec3 st_view_transmittance(float s) { return st_path_transmittance(s); }

#if ST_DENSITY == 1
// Height fog (st_medium_gpu.c sets both): d(y) = e^(-falloff (y - base)).
uniform float st_density_base, st_density_falloff;
#elif ST_DENSITY == 2
// The grid (st_medium_gpu.c): an R32F 3D texture of n voxels, x fastest as
// C's st_density_grid.values, read with texelFetch; st_density_to_local maps
// world points to index coordinates relative to voxel 0 (C: grid_local).
uniform sampler3D st_density_grid;
uniform mat4 st_density_to_local;
uniform ivec3 st_density_size;
#endif

#if ST_DENSITY == 2
vec3 st_grid_local(vec3 x) { return (st_density_to_local * vec4(x, 1.0)).xyz; }
vec3 st_grid_local_dir(vec3 w) { return mat3(st_density_to_local) * w; }

// Trilinear between voxel centres at local coordinates u; 0 outside the
// block (C: grid_sample). Voxel fetches past the last one carry weight 0.
float st_grid_sample(vec3 u) {
    vec3 hi = vec3(st_density_size - 1);
    if (any(lessThan(u, vec3(0.0))) || any(greaterThan(u, hi)) || any(isnan(u))) return 0.0;
    ivec3 i = min(ivec3(floor(u)), st_density_size - 1);
    vec3 f = u - vec3(i);
    ivec3 j = min(i + 1, st_density_size - 1);
    float c000 = texelFetch(st_density_grid, ivec3(i.x, i.y, i.z), 0).r;
    float c100 = texelFetch(st_density_grid, ivec3(j.x, i.y, i.z), 0).r;
    float c010 = texelFetch(st_density_grid, ivec3(i.x, j.y, i.z), 0).r;
    float c110 = texelFetch(st_density_grid, ivec3(j.x, j.y, i.z), 0).r;
    float c001 = texelFetch(st_density_grid, ivec3(i.x, i.y, j.z), 0).r;
    float c101 = texelFetch(st_density_grid, ivec3(j.x, i.y, j.z), 0).r;
    float c011 = texelFetch(st_density_grid, ivec3(i.x, j.y, j.z), 0).r;
    float c111 = texelFetch(st_density_grid, ivec3(j.x, j.y, j.z), 0).r;
    float x00 = mix(c000, c100, f.x), x10 = mix(c010, c110, f.x);
    float x01 = mix(c001, c101, f.x), x11 = mix(c011, c111, f.x);
    return mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
}

// The part of [t0, t1] inside the block [0, n - 1]^3 (C: grid_clip).
bool st_grid_clip(vec3 u0, vec3 du, inout float t0, inout float t1) {
    for (int r = 0; r < 3; r++) {
        float hi = float(st_density_size[r] - 1);
        if (du[r] == 0.0) {
            if (!(u0[r] >= 0.0 && u0[r] <= hi)) return false;
            continue;
        }
        float ta = (0.0 - u0[r]) / du[r], tb = (hi - u0[r]) / du[r];
        t0 = max(t0, min(ta, tb));
        t1 = min(t1, max(ta, tb));
    }
    return t1 > t0;
}

// Exact integral of the trilinear density (C: grid_integral): a DDA over the
// planes u_r = integer, 2-point Gauss-Legendre per piece (a cubic in t
// inside a cell). At most n_x + n_y + n_z + 8 pieces.
float st_grid_integral(vec3 o, vec3 w, float t0, float t1) {
    vec3 u0 = st_grid_local(o), du = st_grid_local_dir(w);
    if (!st_grid_clip(u0, du, t0, t1)) return 0.0;
    vec3 next, stp;
    for (int r = 0; r < 3; r++) {
        float u = u0[r] + t0 * du[r];
        if (du[r] > 0.0) {
            next[r] = t0 + (floor(u) + 1.0 - u) / du[r];
            stp[r] = 1.0 / du[r];
        } else if (du[r] < 0.0) {
            next[r] = t0 + (ceil(u) - 1.0 - u) / du[r];
            stp[r] = -1.0 / du[r];
        } else {
            next[r] = stp[r] = 1e30;
        }
    }
    const float gl = 0.28867513459481287; // 0.5 / sqrt(3)
    float sum = 0.0, t = t0;
    int budget = st_density_size.x + st_density_size.y + st_density_size.z + 8;
    while (t < t1 && budget-- > 0) {
        int r = next.x <= next.y && next.x <= next.z ? 0 : next.y <= next.z ? 1 : 2;
        float te = min(next[r], t1);
        if (te > t) {
            float mid = 0.5 * (t + te), half_ = te - t;
            sum += 0.5 * half_ * (st_grid_sample(u0 + (mid - gl * half_) * du) +
                                  st_grid_sample(u0 + (mid + gl * half_) * du));
            t = te;
        }
        next[r] += stp[r];
    }
    return sum;
}
#endif

#if ST_DENSITY == 1
// Closed form from the segment's lower end (C: st_height_fog_integral); the
// series of (1 - e^-x)/x below x = 1e-3 (float's 1 - e^-x cancels there).
float st_height_fog_depth(float y, float dy, float len) {
    if (!(len > 0.0)) return 0.0;
    float y_low = dy < 0.0 ? y + dy * len : y;
    float x = st_density_falloff * abs(dy) * len;
    float shape = x < 1e-3 ? 1.0 - x * (0.5 - x / 6.0) : (1.0 - exp(-x)) / x;
    float d = exp(min(-st_density_falloff * (y_low - st_density_base), 46.0)); // e^46 ~ 1e20
    return min(len * d * shape, ST_DENSITY_MAX);
}
#endif

float st_density(vec3 x) {
#if ST_DENSITY == 1
    return min(exp(min(-st_density_falloff * (x.y - st_density_base), 46.0)), ST_DENSITY_MAX);
#elif ST_DENSITY == 2
    return st_grid_sample(st_grid_local(x));
#else
    return 1.0;
#endif
}

float st_optical_depth(vec3 o, vec3 w, float t0, float t1) {
    if (!(t1 > t0)) return 0.0;
#if ST_DENSITY == 1
    return st_height_fog_depth(o.y + t0 * w.y, w.y, t1 - t0);
#elif ST_DENSITY == 2
    return min(st_grid_integral(o, w, t0, t1), ST_DENSITY_MAX);
#else
    return t1 - t0;
#endif
}

vec3 st_depth_transmittance(float tau) { return st_transmittance(st_medium_sigma_t(), tau); }

vec3 st_segment_transmittance(vec3 o, vec3 w, float t0, float t1) {
    return st_depth_transmittance(st_optical_depth(o, w, t0, t1));
}

vec3 st_light_transmittance(vec3 x, vec3 to_light, float path) {
#if ST_DENSITY == 0
    return st_path_transmittance(path);
#else
    return st_segment_transmittance(x, to_light, 0.0, path);
#endif
}

vec3 st_view_ray_transmittance(vec3 w, float s) {
#if ST_DENSITY == 0
    return st_view_transmittance(s);
#else
    return st_segment_transmittance(st_cam_pos, w, 0.0, s);
#endif
}
#endif
