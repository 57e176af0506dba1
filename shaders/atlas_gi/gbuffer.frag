// G-buffer atlas: per texel the world position and area a_j, the normal and
// validity, the albedo, and the outgoing radiance L0 = direct + emission
// (common/lighting.glsl; shadow_map's visibility when AG_SHADOW).
// AG_L0_ONLY (a relight in mode=transfer, gbuffer.c): L0 alone, at the
// transfer's texels only.
#include "common/lighting.glsl"
#ifdef AG_SHADOW
#include "shadow_map/visibility.glsl"
#else
float st_visibility(int light, vec3 p, vec3 n) { return 1.0; }
#endif
in vec3 v_world;
in vec3 v_normal;
#ifdef AG_POINTS
flat in vec3 v_albedo;
flat in vec3 v_emission;
#else
uniform vec3 st_albedo;
uniform vec3 st_emission;
#endif
#ifdef AG_L0_ONLY
uniform isampler2D ag_leaf; // the transfer's leaf map: -1 where a texel is not the transfer's
layout(location = 0) out vec4 o_l0;
#else
uniform sampler2D ag_area_tex; // world m^2 per texel, exact (CPU clipping)
layout(location = 0) out vec4 o_pos;    // world position, area
layout(location = 1) out vec4 o_normal; // world normal, valid
layout(location = 2) out vec4 o_albedo;
layout(location = 3) out vec4 o_l0;     // direct + emission
#endif

void main() {
#ifdef AG_L0_ONLY
    if (texelFetch(ag_leaf, ivec2(gl_FragCoord.xy), 0).r == -1) discard;
#endif
#ifdef AG_POINTS
    vec3 albedo = v_albedo, emission = v_emission;
#else
    vec3 albedo = st_albedo, emission = st_emission;
#endif
    vec3 p = v_world;
    float nl = length(v_normal);
    vec3 n = nl > 0.0 ? v_normal / nl : vec3(0.0, 1.0, 0.0);
    vec3 direct = st_direct_light(p, n, albedo);
#ifndef AG_L0_ONLY
    float a = texelFetch(ag_area_tex, ivec2(gl_FragCoord.xy), 0).r;
    bool valid = a > 0.0;
    o_pos = vec4(p, valid ? a : 0.0);
    o_normal = vec4(n, valid ? 1.0 : 0.0);
    o_albedo = vec4(albedo, 1.0);
#endif
    vec3 l0 = direct + emission;
    o_l0 = vec4(all(lessThan(abs(l0), vec3(3e38))) ? l0 : vec3(0.0), 1.0);
}
