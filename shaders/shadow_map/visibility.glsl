// Point-light shadow test against shadow_map's distance cube maps. Included
// into the regular pass (as ST_HAS_VISIBILITY) and by volumetric modules.
#ifndef ST_SHADOW_MAP_VISIBILITY_GLSL
#define ST_SHADOW_MAP_VISIBILITY_GLSL
#include "common/uniforms.glsl"
#define ST_HAS_VISIBILITY 1
uniform samplerCubeArray st_shadow_cubes;
uniform float st_shadow_res;
uniform float st_shadow_bias;  // texels
uniform float st_shadow_slope; // texels per unit tan(incidence)
uniform int st_shadow_pcf;
uniform float st_shadow_pcf_radius;

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
float st_shadow_visibility_biased(int light, vec3 p, float bias, float tan_i) {
    vec3 v = p - st_light_pos[light];
    if (st_shadow_pcf == 0) return st_shadow_test(light, v, length(v), bias);
    // 16 taps on a disk perpendicular to the light direction.
    float d = length(v);
    vec3 dir = v / max(d, 1e-20);
    vec3 t = normalize(abs(dir.y) < 0.9 ? cross(dir, vec3(0, 1, 0)) : cross(dir, vec3(1, 0, 0)));
    vec3 b = cross(dir, t);
    float r = st_shadow_pcf_radius * st_shadow_texel(d);
    float sum = 0.0;
    for (int k = 0; k < 16; k++) {
        // Vogel disk: even coverage for any tap count.
        float rad = r * sqrt((float(k) + 0.5) / 16.0);
        float ang = float(k) * 2.39996323;
        vec3 o = (cos(ang) * t + sin(ang) * b) * rad;
        sum += st_shadow_test(light, v + o, d, bias + rad * tan_i);
    }
    return sum / 16.0;
}

// Surfaces: the bias grows with the slope, since a texel covers a longer
// stretch of distance the more obliquely it sees the surface.
float st_visibility(int light, vec3 p, vec3 n) {
    vec3 l = st_light_pos[light] - p;
    float d = length(l);
    float c = clamp(dot(n, l / max(d, 1e-20)), 1e-3, 1.0);
    float tan_i = min(sqrt(1.0 - c * c) / c, 20.0);
    float bias = st_shadow_texel(d) * (st_shadow_bias + st_shadow_slope * tan_i);
    return st_shadow_visibility_biased(light, p, bias, tan_i);
}

// Points in a volume have no normal: constant bias only.
float st_visibility_point(int light, vec3 p) {
    float d = distance(p, st_light_pos[light]);
    return st_shadow_visibility_biased(light, p, st_shadow_texel(d) * st_shadow_bias, 0.0);
}
#endif
