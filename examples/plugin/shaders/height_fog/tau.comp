// height_fog, pass "tau" (compute, one invocation per pixel): the optical
// depth of the view ray from the camera (y0) over the distance d to the
// surface, direction dir, through density e^(-falloff (y - height)):
//   tau = density e^(-falloff (y0 - height)) (1 - e^(-k)) / (falloff dir.y),  k = falloff d dir.y
// and tau = density e^(-falloff (y0 - height)) d (1 - k/2 + k^2/6) for |k| small
// (a level ray, or falloff 0: a homogeneous fog). -1 where there is no surface.
#include "common/uniforms.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32f, binding = 0) uniform writeonly image2D o_tau; // height_fog.tau, bound by strahl
uniform sampler2D st_gbuffer; // normal, distance from the camera (-1: no surface)
uniform float u_density, u_falloff, u_height;

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(o_tau)))) return; // the last groups overhang
    float d = texelFetch(st_gbuffer, px, 0).w;
    if (d < 0.0) {
        imageStore(o_tau, px, vec4(-1.0));
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
    imageStore(o_tau, px, vec4(tau));
}
