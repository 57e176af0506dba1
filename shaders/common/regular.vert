// Regular pass: world-space position, normal and lightmap UV per vertex
// (regular.geom passes them on).
#include "common/uniforms.glsl"
layout(location = 0) in vec3 st_position;
layout(location = 1) in vec3 st_normal;
layout(location = 2) in vec2 st_uv1;
uniform mat4 st_model;
uniform mat3 st_normal_matrix;
out vec3 g_world;
out vec3 g_normal;
out vec2 g_uv1;
void main() {
    vec4 wp = st_model * vec4(st_position, 1.0);
    g_world = wp.xyz;
    g_normal = st_normal_matrix * st_normal;
    g_uv1 = st_uv1;
    gl_Position = st_view_proj * wp;
}
