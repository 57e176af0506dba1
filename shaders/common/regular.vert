// Regular pass: world-space position, normal and lightmap UV per vertex
// (with the point filter regular.geom passes them on).
#include "common/uniforms.glsl"
layout(location = 0) in vec3 st_position;
layout(location = 1) in vec3 st_normal;
layout(location = 2) in vec2 st_uv1;
uniform mat4 st_model;
uniform mat3 st_normal_matrix;
#ifdef ST_EXACT_PRIMARY // regular.geom reads them (point filter only)
#define v_world g_world
#define v_normal g_normal
#define v_uv1 g_uv1
#endif
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv1;
void main() {
    vec4 wp = st_model * vec4(st_position, 1.0);
    v_world = wp.xyz;
    v_normal = st_normal_matrix * st_normal;
    v_uv1 = st_uv1;
    gl_Position = st_view_proj * wp;
}
