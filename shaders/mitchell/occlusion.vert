// Mitchell occlusion pre-pass: world position and normal for the front-side
// test (emitters emit on their front side only, like the regular pass).
#include "common/uniforms.glsl"
layout(location = 0) in vec3 st_position;
layout(location = 1) in vec3 st_normal;
uniform mat4 st_model;
uniform mat3 st_normal_matrix;
out vec3 v_world;
out vec3 v_normal;
void main() {
    vec4 wp = st_model * vec4(st_position, 1.0);
    v_world = wp.xyz;
    v_normal = st_normal_matrix * st_normal;
    gl_Position = st_view_proj * wp;
}
