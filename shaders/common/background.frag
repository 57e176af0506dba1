// The background seen through the medium (docs/physics.md): where no
// geometry was drawn (depth still at the cleared 1.0), the background radiance
// at the far plane times the view ray's transmittance over far / cos (its
// optical depth where the density varies), cos the
// ray's angle to the view axis, as the reference marches it. Drawn only when
// the scene has both a background and a medium; otherwise the clear colour is
// the background.
#include "common/medium.glsl"
in vec2 v_uv;
uniform vec3 st_background_radiance;
layout(location = 0) out vec4 o_radiance;

vec3 bg_dir(vec2 ndc) {
    vec4 a = st_inv_view_proj * vec4(ndc, -1.0, 1.0);
    vec4 b = st_inv_view_proj * vec4(ndc, 1.0, 1.0);
    return normalize(b.xyz / b.w - a.xyz / a.w);
}

void main() {
    vec2 ndc = gl_FragCoord.xy / st_resolution * 2.0 - 1.0;
    vec3 w = bg_dir(ndc);
    float s = st_far / max(dot(w, bg_dir(vec2(0.0))), 1e-3);
    o_radiance = vec4(st_background_radiance * st_view_ray_transmittance(w, s), 0.0);
    gl_FragDepth = 1.0; // depth test EQUAL: only pixels no geometry covered
}
