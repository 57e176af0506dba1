// Exact visibility: any-hit traversal of the triangle BVH of
// framework/st_bvh.h (layout there) along an open segment. The binding
// points match ST_BVH_BINDING_NODES / _TRIS; st_bvh_bind() binds them.
#ifndef ST_BVH_GLSL
#define ST_BVH_GLSL
layout(std430, binding = 6) readonly buffer st_bvh_nodes_buf { vec4 st_bvh_nodes[]; };
layout(std430, binding = 7) readonly buffer st_bvh_tris_buf { vec4 st_bvh_tris[]; };

// Is the segment o + t (q - o), t in (tmin, 1 - tmin), blocked by a triangle?
// A triangle hit from behind (the ray leaving through its back, winding
// cross(e1, e2) the front) counts only if o lies more than `back` (metres)
// behind its plane: a surface point that float rounding put a hair outside
// a closed room or inside the solid it touches at a crease would otherwise
// shadow itself with the adjacent face (measured across the plane, not
// along the ray, which can be long at grazing angles). As the CPU
// reference's back-side window (tools/reference/ref_geometry.c).
// The index of a triangle that blocks it (into the triangle list, 3 vec4
// each; -1: none): the first one the traversal meets, not the nearest.
int st_bvh_blocker(vec3 o, vec3 q, float tmin, float back) {
    float tmax = 1.0 - tmin;
    vec3 d = q - o;
    vec3 dd = vec3(abs(d.x) < 1e-30 ? 1e-30 : d.x, abs(d.y) < 1e-30 ? 1e-30 : d.y, abs(d.z) < 1e-30 ? 1e-30 : d.z);
    vec3 inv = 1.0 / dd;
    int stack[64];
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        int ni = stack[--sp];
        vec4 lo = st_bvh_nodes[2 * ni], hi = st_bvh_nodes[2 * ni + 1];
        vec3 t0 = (lo.xyz - o) * inv, t1 = (hi.xyz - o) * inv;
        vec3 tn = min(t0, t1), tf = max(t0, t1);
        float a = max(max(tn.x, tn.y), max(tn.z, tmin));
        float b = min(min(tf.x, tf.y), min(tf.z, tmax));
        if (a > b) continue;
        int first = floatBitsToInt(lo.w), count = floatBitsToInt(hi.w);
        if (count > 0) {
            for (int k = 0; k < count; k++) {
                int ti = 3 * (first + k);
                vec3 v0 = st_bvh_tris[ti].xyz, e1 = st_bvh_tris[ti + 1].xyz, e2 = st_bvh_tris[ti + 2].xyz;
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
                if (t > tmin && t < tmax && (det > 0.0 || t * -det > back * length(cross(e1, e2))))
                    return first + k;
            }
        } else if (sp <= 62) {
            stack[sp++] = first;
            stack[sp++] = first + 1;
        }
    }
    return -1;
}

bool st_bvh_occluded_back(vec3 o, vec3 q, float tmin, float back) { return st_bvh_blocker(o, q, tmin, back) >= 0; }

bool st_bvh_occluded_t(vec3 o, vec3 q, float tmin) { return st_bvh_occluded_back(o, q, tmin, 0.0); }

// Between two surface points: the ends' own surfaces lie within 1e-4 of the
// segment's length.
bool st_bvh_occluded(vec3 o, vec3 q) { return st_bvh_occluded_t(o, q, 1e-4); }

// Which triangle blocks the segment, a hit from either side counting (-1:
// none; see st_bvh_blocker). toth's exact shadow boundaries take the blocking
// triangle's shadow volume from it (toth/visibility.glsl).
int st_bvh_occluder(vec3 o, vec3 q, float tmin) { return st_bvh_blocker(o, q, tmin, 0.0); }

// Triangle i of the list: a vertex and the two edges from it.
void st_bvh_triangle(int i, out vec3 v0, out vec3 e1, out vec3 e2) {
    v0 = st_bvh_tris[3 * i].xyz;
    e1 = st_bvh_tris[3 * i + 1].xyz;
    e2 = st_bvh_tris[3 * i + 2].xyz;
}
#endif
