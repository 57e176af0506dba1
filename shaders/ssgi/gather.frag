// ssgi: one bounce per pixel from N Hammersley samples over the camera's
// G-buffer, with atlas_gi's estimators. A sample pixel j is the surface
// patch it sees: area = (pixel solid angle) d_j^2 / max(|cos view|, min_cos),
// the pixel solid angle being s^2 cos^3(alpha) for a pixel of side s on the
// image plane at distance 1 and alpha its angle to the optical axis.
#include "common/medium.glsl"
#include "common/estimator.glsl"
uniform sampler2D st_hdr_in;     // direct + emission, seen through the medium (the regular pass)
uniform sampler2D st_gbuffer;    // normal, distance (-1: no surface)
uniform sampler2D st_albedo_tex; // albedo, front side
uniform sampler1D ss_hammersley;
uniform int ss_samples;
uniform int ss_estimator;
uniform int ss_display; // 0 combined, 1 indirect
uniform float ss_min_cos;
layout(location = 0) out vec4 o_color;

vec3 ray_dir(ivec2 px, vec2 size) {
    vec2 ndc = (vec2(px) + 0.5) / size * 2.0 - 1.0;
    vec4 a = st_inv_view_proj * vec4(ndc, -1.0, 1.0), b = st_inv_view_proj * vec4(ndc, 1.0, 1.0);
    return normalize(b.xyz / b.w - a.xyz / a.w);
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(st_gbuffer, 0);
    vec2 fsize = vec2(size);
    vec3 hdr = texelFetch(st_hdr_in, t, 0).rgb;
    vec4 g = texelFetch(st_gbuffer, t, 0);
    vec4 alb = texelFetch(st_albedo_tex, t, 0);
    if (g.w < 0.0 || alb.a < 0.5) {
        o_color = vec4(ss_display == 1 ? vec3(0.0) : hdr, 1.0);
        return;
    }
    vec3 x = st_cam_pos + ray_dir(t, fsize) * g.w;
    vec3 nx = g.xyz;
    vec3 fwd = -vec3(st_view[0][2], st_view[1][2], st_view[2][2]);
    float s = 2.0 * tan(0.5 * st_fov_y) / fsize.y;
    vec3 sum = vec3(0.0);
    for (int i = 0; i < ss_samples; i++) {
        vec2 u = texelFetch(ss_hammersley, i, 0).rg;
        ivec2 j = min(ivec2(u * fsize), size - 1);
        vec4 gj = texelFetch(st_gbuffer, j, 0);
        if (gj.w < 0.0 || texelFetch(st_albedo_tex, j, 0).a < 0.5) continue; // nothing, or a back side
        vec3 L = texelFetch(st_hdr_in, j, 0).rgb;
        if (L == vec3(0.0)) continue;
        vec3 dj = ray_dir(j, fsize);
        vec3 pj = st_cam_pos + dj * gj.w;
        float ca = max(dot(dj, fwd), 1e-3);
        float area = s * s * ca * ca * ca * gj.w * gj.w / max(abs(dot(gj.xyz, dj)), ss_min_cos);
        vec3 d = pj - x;
        float d2 = dot(d, d);
        if (d2 < 1e-20) continue;
        vec3 w = d * inversesqrt(d2);
        float cx = dot(nx, w), cj = -dot(gj.xyz, w);
        if (cx <= 0.0 || cj <= 0.0) continue;
        // hdr holds L0_j e^(-sigma_t d_j) (the regular pass applies the view
        // ray's extinction); combined needs L0_j e^(-sigma_t (|x - pj| + d_x))
        // and the indirect display (a surface AOV, like the reference's) L0_j
        // e^(-sigma_t |x - pj|). For combined the triangle camera, x, pj keeps
        // the path >= 0: where hdr underflowed, the true contribution is
        // smaller still. The display's exponent is capped against overflow.
        float path = sqrt(d2) - gj.w + (ss_display == 1 ? 0.0 : g.w);
        vec3 tr = exp(min(-st_medium_sigma_t() * path, vec3(80.0)));
        sum += L * tr * ag_sample_weight(ss_estimator, cx, cj, area, d2);
    }
    // Combined: L1 is the bounce seen through the medium, like hdr.
    vec3 L1 = ag_estimate(ss_estimator, alb.rgb, sum, fsize.x * fsize.y, float(ss_samples));
    o_color = vec4(ss_display == 1 ? L1 : hdr + L1, 1.0);
}
