// height_fog: L = L_surface T + radiance (1 - T), T = e^(-tau), with tau the
// integral of density e^(-falloff (y - height)) along the view ray from the
// camera (y0) over the distance d to the surface, direction dir:
//   tau = density e^(-falloff (y0 - height)) (1 - e^(-k)) / (falloff dir.y),  k = falloff d dir.y
// and tau = density e^(-falloff (y0 - height)) d (1 - k/2 + k^2/6) for |k| small
// (a level ray, or falloff 0: a homogeneous fog).
#include "common/uniforms.glsl"
uniform sampler2D st_hdr_in;
uniform sampler2D st_gbuffer; // normal, distance from the camera (-1: no surface)
uniform float u_density, u_falloff, u_height, u_radiance;
layout(location = 0) out vec4 o_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 L = texelFetch(st_hdr_in, px, 0).rgb;
    float d = texelFetch(st_gbuffer, px, 0).w;
    if (d < 0.0) {
        o_color = vec4(L, 1.0);
        return;
    }
    // The view ray through this pixel's centre.
    vec2 ndc = (vec2(px) + 0.5) / st_resolution * 2.0 - 1.0;
    vec4 a = st_inv_view_proj * vec4(ndc, -1.0, 1.0), b = st_inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 dir = normalize(b.xyz / b.w - a.xyz / a.w);
    float k = u_falloff * d * dir.y;
    float base = u_density * exp(-u_falloff * (st_cam_pos.y - u_height));
    float tau = abs(k) < 1e-3 ? base * d * (1.0 - k / 2.0 + k * k / 6.0)
                              : base * (1.0 - exp(-k)) / (u_falloff * dir.y);
    float T = exp(-tau);
    o_color = vec4(L * T + u_radiance * (1.0 - T), 1.0);
}
