// Visibility for the gather: any-hit traversal of the BVH (modules/atlas_gi/
// bvh.h for the layout) along the open segment between two surface points.
#ifndef AG_BVH_GLSL
#define AG_BVH_GLSL
layout(std430, binding = 0) readonly buffer ag_bvh_nodes { vec4 ag_nodes[]; };
layout(std430, binding = 1) readonly buffer ag_bvh_tris { vec4 ag_tris[]; };

// Is the segment o + t (q - o), t in (1e-4, 1 - 1e-4), blocked by a triangle?
bool ag_occluded(vec3 o, vec3 q) {
    const float tmin = 1e-4, tmax = 1.0 - 1e-4;
    vec3 d = q - o;
    vec3 dd = vec3(abs(d.x) < 1e-30 ? 1e-30 : d.x, abs(d.y) < 1e-30 ? 1e-30 : d.y, abs(d.z) < 1e-30 ? 1e-30 : d.z);
    vec3 inv = 1.0 / dd;
    int stack[64];
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        int ni = stack[--sp];
        vec4 lo = ag_nodes[2 * ni], hi = ag_nodes[2 * ni + 1];
        vec3 t0 = (lo.xyz - o) * inv, t1 = (hi.xyz - o) * inv;
        vec3 tn = min(t0, t1), tf = max(t0, t1);
        float a = max(max(tn.x, tn.y), max(tn.z, tmin));
        float b = min(min(tf.x, tf.y), min(tf.z, tmax));
        if (a > b) continue;
        int first = floatBitsToInt(lo.w), count = floatBitsToInt(hi.w);
        if (count > 0) {
            for (int k = 0; k < count; k++) {
                int ti = 3 * (first + k);
                vec3 v0 = ag_tris[ti].xyz, e1 = ag_tris[ti + 1].xyz, e2 = ag_tris[ti + 2].xyz;
                // Moller-Trumbore.
                vec3 pv = cross(d, e2);
                float det = dot(e1, pv);
                if (abs(det) < 1e-30) continue;
                float id = 1.0 / det;
                vec3 tv = o - v0;
                float u = dot(tv, pv) * id;
                if (u < 0.0 || u > 1.0) continue;
                vec3 qv = cross(tv, e1);
                float v = dot(d, qv) * id;
                if (v < 0.0 || u + v > 1.0) continue;
                float t = dot(e2, qv) * id;
                if (t > tmin && t < tmax) return true;
            }
        } else if (sp <= 62) {
            stack[sp++] = first;
            stack[sp++] = first + 1;
        }
    }
    return false;
}
#endif
