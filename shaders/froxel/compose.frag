// froxel pass 3: adds the in-scattered light at full resolution to what the
// camera sees (hdr_in, already the surface's radiance times the view ray's
// transmittance: the regular pass owns that, docs/physics.md). A pixel at
// view depth z inside slice k takes the integral to the slice's start and
// the partial step of the slice's source over the rest of its own ray,
// interpolated bilinearly between the columns around it. Where no surface
// is seen the ray ends at the far plane (far / cos), as the reference
// marches it; nothing is added beyond the grid's far.
#include "common/uniforms.glsl"
#include "common/medium.glsl"
#include "shadow_map/visibility.glsl"
#include "froxel/grid.glsl"
uniform sampler2D st_hdr_in;
uniform sampler2D st_gbuffer;
uniform sampler2DArray froxel_inject_tex;
uniform sampler2DArray froxel_integrated_tex;
layout(location = 0) out vec4 o_radiance;

// The near field of positioned light l along the pixel's ray [0, s]: the
// integral of sigma_s phase I f e^(-sigma_t (t + d)) R^2 / (d^2 (d^2 + R^2))
// (grid.glsl), unshadowed, by Gauss-Legendre in the angle theta seen from
// the light (t - foot = h tan theta; dt / (h^2 + t^2) = dtheta / h), where
// the kernel is R^2 / (h (H^2 + h^2 tan^2 theta)), H^2 = h^2 + R^2: smooth
// in theta, exact as R -> 0. Its mass lies within about max(h, R) of the
// ray's point nearest the light, whose shadow_map visibility it takes (one
// lookup: a wall between the ray and a light just behind it still shadows).
const float FROXEL_GL_X[4] = float[4](0.1834346425, 0.5255324099, 0.7966664774, 0.9602898565);
const float FROXEL_GL_W[4] = float[4](0.3626837834, 0.3137066459, 0.2223810345, 0.1012285363);

// Density times the view's and the light's transmittance at x, t along
// the view ray dir and d from the light (exact for every density: the near
// field is small, 8 points a pixel).
vec3 froxel_near_medium(vec3 dir, float t, vec3 x, vec3 to_light, float d) {
#if ST_DENSITY_VARIES
    float tau = st_optical_depth(st_cam_pos, dir, 0.0, t) + st_optical_depth(x, to_light, 0.0, d);
    return st_density(x) * st_depth_transmittance(tau);
#else
    return exp(-st_medium_sigma_t() * (t + d));
#endif
}

vec3 froxel_near(int l, vec3 dir, float s) {
    float R = froxel_near_radius(l);
    vec3 v = st_light_pos[l] - st_cam_pos;
    float foot = dot(v, dir);
    float h = max(length(v - foot * dir), 1e-4 * R);
    float H2 = h * h + R * R;
    float lo = 0.0, hi = s;
    if (ST_LIGHT_IS(l, 2) && !froxel_spot_range(l, st_cam_pos, dir, lo, hi)) return vec3(0.0);
    float ta = atan((lo - foot) / h), tb = atan((hi - foot) / h);
    float mid = 0.5 * (ta + tb), half_len = 0.5 * (tb - ta);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 8; k++) {
        float th = mid + half_len * (k < 4 ? -FROXEL_GL_X[k] : FROXEL_GL_X[k - 4]);
        float tr = h * tan(th), t = foot + tr;
        vec3 x = st_cam_pos + t * dir;
        vec3 to_light = st_light_pos[l] - x;
        float d = length(to_light);
        to_light /= max(d, 1e-30);
        float f = 1.0;
        if (ST_LIGHT_IS(l, 2)) { // spot: glTF's falloff (common/lighting.glsl)
            float a = clamp(-dot(to_light, st_light_dir[l]) * st_light_shape[l].x + st_light_shape[l].y, 0.0, 1.0);
            f = a * a;
        }
        float kern = R * R / (h * (H2 + tr * tr));
        float w = FROXEL_GL_W[k < 4 ? k : k - 4] * half_len;
        sum += w * kern * f * st_phase(st_phase_kind, dot(to_light, dir), st_phase_g) * froxel_near_medium(dir, t, x, to_light, d);
    }
    vec3 nearest = st_cam_pos + clamp(foot, lo, hi) * dir;
    if (all(equal(sum, vec3(0.0)))) return sum;
    return st_sigma_s * st_light_intensity[l] * sum * st_visibility_point(l, nearest);
}

// The near field of light l averaged over the pixel's square in a
// box-filtered frame (st_filter_sample > 0). Next to the light's projection
// the near field grows like 1/h (h the ray's distance from the light), so one
// jittered point per frame has a huge, slowly shrinking variance there (at
// the light's own pixel a log-divergent one): the still hit the 1024-frame
// cap on spot_fog at 128 x 128, the apex's pixel holding half the squared
// error against a 4096-spp box reference (now 380 frames). Within 8 pixels of the light (h at the light's distance) the frame
// takes m x m points, one per stratum of the pixel, all at the frame's own
// offset inside its stratum (the camera's jitter, Halton), so the frames
// still cover the square uniformly and each returns nearly the mean;
// m = 8 within 2 pixels, 4 up to 8. The surface depth s is the frame's
// sample's for all of them. The point filter and a still's first frame keep
// the single centre ray (bit-identical).
// The frame's sample offset from the pixel centre in pixels (NDC axes): the
// jittered projection's shift (st_filter.c's jitter_matrices; 0 on the point
// filter and a still's first frame).
vec2 froxel_jitter_px() { return vec2(st_proj[2][0], st_proj[2][1]) * st_resolution * 0.5; }

vec3 froxel_near_pixel(int l, vec2 uv, float s) {
    vec2 ndc = uv * 2.0 - 1.0;
    int m = 1;
    if (st_filter_sample > 0) {
        vec3 dir = froxel_ndc_dir(ndc), v = st_light_pos[l] - st_cam_pos;
        float pixel = max(dot(v, dir), 1e-6) * 2.0 * tan(0.5 * st_fov_y) / st_resolution.y;
        float h = length(v - dot(v, dir) * dir) / pixel;
        m = h < 2.0 ? 8 : h < 8.0 ? 4 : 1;
    }
    // One loop, so that llvmpipe runs the near field once where no pixel
    // needs more.
    vec2 jit = froxel_jitter_px();
    vec3 sum = vec3(0.0);
    for (int k = 0; k < m * m; k++) {
        vec2 q = (vec2(k % m, k / m) + jit + 0.5) / float(m) - 0.5;
        sum += froxel_near(l, froxel_ndc_dir(ndc + (q - jit) * 2.0 / st_resolution), s);
    }
    return sum / float(m * m);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 base = texelFetch(st_hdr_in, px, 0);
    vec4 gb = texelFetch(st_gbuffer, px, 0);
    vec2 uv = gl_FragCoord.xy / st_resolution;
    float c = froxel_cos(froxel_ndc_dir(uv * 2.0 - 1.0));
    float s = gb.w >= 0.0 ? gb.w : st_far / c;
    float z = min(s * c, froxel_far);
    float n = float(froxel_grid.z);
    float k = clamp(floor(froxel_slice(z) * n), 0.0, n - 1.0);
    // The columns around the pixel, bilinear. A still's jittered frame that
    // reuses its first frame's grid (centred projection) reads it at this
    // frame's sample, jit pixels off the centre (froxel_jitter_px).
    vec2 cuv = uv;
    if (froxel_reuse != 0) cuv += froxel_jitter_px() / st_resolution;
    vec4 prev = k > 0.0 ? texture(froxel_integrated_tex, vec3(cuv, k - 1.0)) : vec4(0.0);
    vec4 src = texture(froxel_inject_tex, vec3(cuv, k));
    float dt = max(z - froxel_depth(k / n), 0.0) / c;
    vec3 sigma_t = st_medium_sigma_t();
    vec3 L = prev.rgb + exp(-sigma_t * prev.a) * st_step_inscatter(src.rgb, src.a * sigma_t, dt);
    if (froxel_near_field != 0)
        for (int l = 0; l < st_num_lights; l++)
            if (ST_LIGHT_POSITIONED(l)) L += froxel_near_pixel(l, uv, s);
    o_radiance = vec4(base.rgb + L, base.a);
}
