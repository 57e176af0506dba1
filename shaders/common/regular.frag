// Regular pass: Lambertian direct light from point lights (docs/physics.md:
// L = rho/pi * I * cos / d^2 * V * e^(-sigma_t d)) plus emission, plus
// indirect light when a module provides it, as the camera sees it: times the
// view ray's transmittance e^(-sigma_t tau) (tau = s when homogeneous) whenever the scene has a medium
// (whichever volumetric module runs, or none; they add in-scattered light). Modules hook in through their
// regular_include, which the world expands before this file.
#include "common/lighting.glsl"
#include "common/facet.glsl"
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv1;
#ifdef ST_EXACT_PRIMARY // regular.geom, point filter only (st_world_build_regular)
flat in vec3 v_tri0, v_tri1, v_tri2;
flat in int v_exact;
#else
const vec3 v_tri0 = vec3(0.0), v_tri1 = vec3(0.0), v_tri2 = vec3(0.0);
const int v_exact = 0; // the rasteriser's coverage
#endif
uniform vec3 st_albedo;
uniform vec3 st_emission;
uniform int st_double_sided;
layout(location = 0) out vec4 o_radiance;
layout(location = 1) out vec4 o_gbuffer; // world normal, distance to the camera
layout(location = 2) out vec4 o_albedo;

#ifndef ST_HAS_VISIBILITY
float st_visibility(int light, vec3 p, vec3 n) { return 1.0; }
#endif
#ifndef ST_HAS_INDIRECT
vec3 st_indirect(vec3 p, vec3 n, vec2 uv1) { return vec3(0.0); }
#endif

// Whether this fragment stays, by the exact ray through its sample
// position (regular.geom drew the triangle and a ring around it): the ray's
// side of each edge, seen from the camera. The triangle keeps what the ray
// does not clearly miss, the ring what it clearly hits; within float
// rounding of an edge (2^-22 of the products' size) the rasteriser's
// coverage stands. `precise` keeps the products unfused.
bool st_primary_hit() {
    if (v_exact == 0) return true;
    vec2 ndc = gl_FragCoord.xy / st_resolution * 2.0 - 1.0;
    // The view-space direction for that NDC point (st_proj carries the box
    // filter's jitter in its third column), then to world space.
    vec3 dv = vec3((ndc.x + st_proj[2][0]) / st_proj[0][0],
                   (ndc.y + st_proj[2][1]) / st_proj[1][1], -1.0);
    precise vec3 d = transpose(mat3(st_view)) * dv;
    precise vec3 a = v_tri0 - st_cam_pos, b = v_tri1 - st_cam_pos, c = v_tri2 - st_cam_pos;
    precise vec3 e = vec3(dot(d, cross(a, b)), dot(d, cross(b, c)), dot(d, cross(c, a)));
    float la = length(a), lb = length(b), lc = length(c);
    vec3 tol = 2.384185791e-7 * length(d) * vec3(la * lb, lb * lc, lc * la);
    // Inside that band (float cross products of long, far edges cancel):
    // the same products in double, whose rounding is 2^-29 smaller, so the
    // band shrinks to the float-rounded ray direction's own error (2^-21 of
    // the angle to the edge's plane; a centre exactly on an edge stays in it
    // and keeps the rasteriser's coverage). godrays_window at 512^2: a
    // centre 0.00056 px beside a crease was -0.92 of the float band.
    if (any(lessThan(abs(e), tol))) {
        dvec3 dd = dvec3(d), cp = dvec3(st_cam_pos);
        precise dvec3 da = dvec3(v_tri0) - cp, db = dvec3(v_tri1) - cp, dc = dvec3(v_tri2) - cp;
        precise dvec3 nab = cross(da, db), nbc = cross(db, dc), nca = cross(dc, da);
        precise dvec3 ed = dvec3(dot(dd, nab), dot(dd, nbc), dot(dd, nca));
        dvec3 lab = dvec3(length(da) * length(db), length(db) * length(dc),
                          length(dc) * length(da));
        dvec3 td = length(dd) * (3.6e-15lf * lab +
                                 4.8e-7lf * dvec3(length(nab), length(nbc), length(nca)));
        e = vec3(ed / max(td, dvec3(1e-300lf)));
        tol = vec3(1.0);
    }
    if (v_exact == 1) return all(greaterThanEqual(e, -tol)) || all(lessThanEqual(e, tol));
    return all(greaterThan(e, tol)) || all(lessThan(e, -tol));
}

void main() {
    vec3 p = v_world;
    vec3 n = normalize(v_normal);
    vec3 to_cam = st_cam_pos - p;
    // Front side = the side of the facet that the shading normal is on; the
    // back side of a one-sided surface is black but still occludes. The
    // facet's own normal decides which side is seen (common/facet.glsl;
    // meshes_direct: 12 pixels on Suzanne's head were black).
    bool front = st_facet_front(p, n, st_cam_pos);
    if (!st_primary_hit()) discard;
    if (!front && st_double_sided != 0) {
        n = -n;
        front = true;
    }
    vec3 direct = vec3(0.0);
    vec3 indirect = vec3(0.0);
    vec3 emission = vec3(0.0);
    if (front) {
        direct = st_direct_light(p, n, st_albedo);
        emission = st_emission;
        indirect = st_indirect(p, n, v_uv1);
    }
    float s = length(to_cam);
#ifdef ST_HAS_COMPOSE
    // A module's display mode may show a surface AOV (atlas_gi
    // display=indirect, as the reference's --aov indirect: the surface's
    // radiance before the view ray); st_compose_viewed says whether what it
    // returns is seen through the medium.
    vec3 L = st_compose(direct, emission, indirect, p, n, v_uv1);
    if (st_compose_viewed()) L *= st_view_ray_transmittance(-to_cam / max(s, 1e-30), s);
#else
    vec3 L = (direct + emission + indirect) * st_view_ray_transmittance(-to_cam / max(s, 1e-30), s);
#endif
    o_radiance = vec4(L, 1.0);
    o_gbuffer = vec4(n, s);
    o_albedo = vec4(st_albedo, front ? 1.0 : 0.0);
}
