// Shadow test against shadow_map's distance cube maps (point and spot lights)
// and its cascades (directional lights). Included into the regular pass (as
// ST_HAS_VISIBILITY) and by volumetric modules.
#ifndef ST_SHADOW_MAP_VISIBILITY_GLSL
#define ST_SHADOW_MAP_VISIBILITY_GLSL
#include "common/uniforms.glsl"
#include "common/bvh.glsl"
#ifdef ST_FRAGMENT
#include "common/facet.glsl"
#endif
#define ST_HAS_VISIBILITY 1
uniform samplerCubeArray st_shadow_cubes;
uniform float st_shadow_res;     // cube face size in texels
uniform float st_shadow_sun_res; // cascade size in texels
uniform float st_shadow_bias;  // texels
uniform float st_shadow_slope; // texels per unit tan(incidence)
uniform int st_shadow_pcf;
uniform float st_shadow_pcf_radius;
uniform int st_shadow_refine; // 1: ambiguous surface lookups traced exactly (common/bvh.glsl)
// Directional lights (modules/shadow_map/cascades.h): slot per light (-1:
// none), cascades ending at view depths st_shadow_cascade_far, each a square
// (centre u, v; half size) in the light's basis, layer slot * 4 + cascade.
uniform sampler2DArray st_shadow_suns;
uniform int st_shadow_sun_slot[ST_MAX_LIGHTS];
uniform int st_shadow_cascade_count;
uniform float st_shadow_cascade_far[4];
uniform vec4 st_shadow_cascade_rect[ST_MAX_LIGHTS * 4];

// The basis rule of cascades.c: any axis not nearly parallel to L.
void st_shadow_sun_basis(vec3 L, out vec3 u, out vec3 v) {
    u = normalize(cross(L, abs(L.y) < 0.9 ? vec3(0, 1, 0) : vec3(1, 0, 0)));
    v = cross(L, u);
}

// A directional light: the cascade covering p's view depth; its texels are
// 2 half / res wide. Outside every fitted square nothing is known: lit.
// `ambiguous` (refine): 8 taps two texels around p do not all agree with
// the centre, the centre is lit only thanks to the bias, or p lies outside
// every fitted square (never with PCF, whose filtered edge is wanted).
float st_shadow_sun_amb(int light, vec3 p, float bias_texels, float tan_i, bool probe, out bool ambiguous) {
    ambiguous = false;
    int slot = st_shadow_sun_slot[light];
    if (slot < 0) return 1.0;
    float depth = -(st_view * vec4(p, 1.0)).z;
    int c = 0;
    while (c < st_shadow_cascade_count - 1 && depth > st_shadow_cascade_far[c]) c++;
    vec4 r = st_shadow_cascade_rect[slot * 4 + c];
    vec3 L = -st_light_dir[light], u, v;
    st_shadow_sun_basis(L, u, v);
    vec2 uv = (vec2(dot(p, u), dot(p, v)) - r.xy) / r.z * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        ambiguous = probe; // nothing known here: the exact ray decides
        return 1.0;
    }
    float path = st_light_shape[light].z - dot(p, L);
    float texel = 2.0 * r.z / st_shadow_sun_res;
    float bias = texel * bias_texels;
    float layer = float(slot * st_shadow_cascade_count + c);
    if (st_shadow_pcf == 0) {
        float stored = texture(st_shadow_suns, vec3(uv, layer)).r;
        float vis = path - bias <= stored ? 1.0 : 0.0;
        // Lit only thanks to the bias: something sits in front by more than
        // half of it (a near occluder; at grazing incidence it can be the
        // receiver's own surface, and the ray then only costs time).
        ambiguous = probe && vis > 0.0 && stored < path - 0.5 * bias;
        for (int k = 0; probe && k < 8 && !ambiguous; k++) {
            float ang = float(k) * 0.78539816;
            vec2 o = vec2(cos(ang), sin(ang)) * 2.0 / st_shadow_sun_res;
            float tap = texture(st_shadow_suns, vec3(uv + o, layer)).r;
            ambiguous = (path - bias - 2.0 * texel * tan_i <= tap ? 1.0 : 0.0) != vis;
        }
        return vis;
    }
    float sum = 0.0;
    // The trip count is a uniform, not 16: a constant loop is unrolled, and
    // llvmpipe runs the unrolled taps (masked) even where PCF is off.
    for (int k = 0; k < (st_shadow_pcf != 0 ? 16 : 0); k++) { // Vogel disk, as for the cubes
        float rad = st_shadow_pcf_radius * sqrt((float(k) + 0.5) / 16.0);
        float ang = float(k) * 2.39996323;
        vec2 o = vec2(cos(ang), sin(ang)) * rad / st_shadow_sun_res;
        float stored = texture(st_shadow_suns, vec3(uv + o, layer)).r;
        sum += path - bias - rad * texel * tan_i <= stored ? 1.0 : 0.0;
    }
    // PCF softens edges on purpose: its filtered value stands.
    return sum / 16.0;
}

float st_shadow_sun(int light, vec3 p, float bias_texels, float tan_i) {
    bool ambiguous;
    return st_shadow_sun_amb(light, p, bias_texels, tan_i, false, ambiguous);
}

// World size of one cube texel at distance d (a face spans 2d).
float st_shadow_texel(float d) { return 2.0 * d / st_shadow_res; }

// Compares the receiver's distance d with what the map stores along dir.
float st_shadow_test(int light, vec3 dir, float d, float bias) {
    float stored = texture(st_shadow_cubes, vec4(dir, float(light))).r;
    return d - bias <= stored ? 1.0 : 0.0;
}

// Visibility of point p from light `light`, bias in metres. PCF taps look
// along neighbouring directions but compare the receiver's own distance, so
// a tap on a sloped receiver needs tan_i times its offset as extra bias.
// `ambiguous` as for st_shadow_sun_amb (computed only when probe is set; never
// with PCF).
float st_shadow_visibility_amb(int light, vec3 p, float bias, float tan_i, bool probe, out bool ambiguous) {
    ambiguous = false;
    vec3 v = p - st_light_pos[light];
    float d = length(v);
    if (st_shadow_pcf == 0 && !probe) return st_shadow_test(light, v, d, bias);
    vec3 dir = v / max(d, 1e-20);
    vec3 t = normalize(abs(dir.y) < 0.9 ? cross(dir, vec3(0, 1, 0)) : cross(dir, vec3(1, 0, 0)));
    vec3 b = cross(dir, t);
    if (st_shadow_pcf == 0) {
        float stored = texture(st_shadow_cubes, vec4(v, float(light))).r;
        float vis = d - bias <= stored ? 1.0 : 0.0;
        // Lit only thanks to the bias: something sits in front by more than
        // half of it (a near occluder; at grazing incidence it can be the
        // receiver's own surface, and the ray then only costs time).
        ambiguous = vis > 0.0 && stored < d - 0.5 * bias;
        // An edge within two texels of p puts one of 8 taps on its other side.
        float rad = 2.0 * st_shadow_texel(d);
        for (int k = 0; k < 8 && !ambiguous; k++) {
            float ang = float(k) * 0.78539816;
            vec3 o = (cos(ang) * t + sin(ang) * b) * rad;
            ambiguous = st_shadow_test(light, v + o, d, bias + rad * tan_i) != vis;
        }
        return vis;
    }
    // 16 taps on a disk perpendicular to the light direction.
    float r = st_shadow_pcf_radius * st_shadow_texel(d);
    float sum = 0.0;
    for (int k = 0; k < (st_shadow_pcf != 0 ? 16 : 0); k++) { // (see st_shadow_sun_amb)
        // Vogel disk: even coverage for any tap count.
        float rad = r * sqrt((float(k) + 0.5) / 16.0);
        float ang = float(k) * 2.39996323;
        vec3 o = (cos(ang) * t + sin(ang) * b) * rad;
        sum += st_shadow_test(light, v + o, d, bias + rad * tan_i);
    }
    // PCF softens edges on purpose: its filtered value stands.
    return sum / 16.0;
}

float st_shadow_visibility_biased(int light, vec3 p, float bias, float tan_i) {
    bool ambiguous;
    return st_shadow_visibility_amb(light, p, bias, tan_i, false, ambiguous);
}

// The exact answer (refine): is the segment from surface point p (normal n,
// facing the light) to the light free of triangles? It starts a hair off the
// surface along n, 1e-5 of its length (the reference offsets 1e-5 of the
// scene's diagonal), so p's own triangle does not count; a larger offset
// moves the edges of grazing shadows visibly.
float st_shadow_exact(int light, vec3 p, vec3 n) {
    vec3 q;
    if (ST_LIGHT_IS(light, 1)) {
        vec3 L = -st_light_dir[light];
        q = p + L * max(st_light_shape[light].z - dot(p, L), 1e-3);
    } else {
        q = st_light_pos[light];
    }
    float len = distance(p, q);
    vec3 o = p + n * (1e-5 * len);
    // A face p lies behind by float rounding (the ceiling, for a wall pixel
    // at the crease) is not an occluder; rounding scales with |p| too.
    vec3 ap = abs(p);
    float back = 2e-5 * max(len, max(ap.x, max(ap.y, ap.z)));
    return st_bvh_occluded_back(o, q, 1e-6, back) ? 0.0 : 1.0;
}

// Whether p's own facet turns its back on the light, on the side whose
// shading normal is n: then the exact ray (the reference's, Cycles') leaves
// through the facet itself and p is in shadow, although a smooth mesh's
// interpolated normal may still face the light near the terminator; the
// shadow map, biased, sees nothing there (issue 20, spot_room: pixels at
// Suzanne's ear lit at 0.57 where the reference is black). The facet normal
// comes from p's derivatives, which stay in p's triangle: fragment shaders
// rasterising surfaces only (the regular pass, atlas_gi's G-buffer). GLSL
// leaves derivatives in non-uniform control flow (the lights' loop)
// undefined; llvmpipe takes them from all four lanes of the quad, where p,
// the interpolated input, holds its value before any branch (a port to a
// GPU should compute the facet normal before the loop). Where they vanish
// (atlas_gi's points) nothing is known.
bool st_shadow_facet_away(vec3 p, vec3 n, vec3 to_light) {
#ifdef ST_FRAGMENT
    vec3 ng = st_facet_normal(p, n);
    return dot(ng, ng) > 0.0 && dot(ng, to_light) <= 0.0;
#else
    return false;
#endif
}

// Surfaces: the bias grows with the slope, since a texel covers a longer
// stretch of distance the more obliquely it sees the surface.
float st_visibility(int light, vec3 p, vec3 n) {
    bool probe = st_shadow_refine != 0, ambiguous = false;
    vec3 to_light = ST_LIGHT_IS(light, 1) ? -st_light_dir[light] : st_light_pos[light] - p;
    if (st_shadow_facet_away(p, n, to_light)) return 0.0;
    float vis = 1.0;
    if (ST_LIGHT_IS(light, 1)) { // directional
        float c = clamp(dot(n, -st_light_dir[light]), 1e-3, 1.0);
        float tan_i = min(sqrt(1.0 - c * c) / c, 20.0);
        vis = st_shadow_sun_amb(light, p, st_shadow_bias + st_shadow_slope * tan_i, tan_i, probe, ambiguous);
        if (st_shadow_sun_slot[light] < 0) return vis;
    } else if (ST_LIGHT_POSITIONED(light)) {
        vec3 l = st_light_pos[light] - p;
        float d = length(l);
        float c = clamp(dot(n, l / max(d, 1e-20)), 1e-3, 1.0);
        float tan_i = min(sqrt(1.0 - c * c) / c, 20.0);
        float bias = st_shadow_texel(d) * (st_shadow_bias + st_shadow_slope * tan_i);
        vis = st_shadow_visibility_amb(light, p, bias, tan_i, probe, ambiguous);
    }
    return ambiguous ? st_shadow_exact(light, p, n) : vis;
}

// Points in a volume have no normal: constant bias only.
float st_visibility_point(int light, vec3 p) {
    if (ST_LIGHT_IS(light, 1)) return st_shadow_sun(light, p, st_shadow_bias, 0.0);
    if (!ST_LIGHT_POSITIONED(light)) return 1.0;
    float d = distance(p, st_light_pos[light]);
    return st_shadow_visibility_biased(light, p, st_shadow_texel(d) * st_shadow_bias, 0.0);
}
#endif
