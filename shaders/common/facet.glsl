// Which side of a triangle the camera sees, decided as the reference (the
// winding) and Cycles (the geometric normal) decide it: by the facet's own
// normal, from the position's screen derivatives (they stay in the
// triangle), turned to the side the shading normal n is on. At a smooth
// mesh's silhouette the interpolated normal turns away from a camera that
// sees the facet's front; taken for the side, it makes lit or emitting
// pixels there black (issue 20). Derivatives: call in uniform control flow.
#ifndef ST_FACET_GLSL
#define ST_FACET_GLSL
// The facet's normal on the side of n (zero where the derivatives vanish).
vec3 st_facet_normal(vec3 p, vec3 n) {
    vec3 ng = cross(dFdx(p), dFdy(p));
    return dot(ng, n) < 0.0 ? -ng : ng;
}
bool st_facet_front(vec3 p, vec3 n, vec3 eye) {
    return dot(st_facet_normal(p, n), eye - p) >= 0.0;
}
#endif
