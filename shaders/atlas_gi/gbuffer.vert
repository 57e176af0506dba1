// G-buffer atlas: each vertex goes to its atlas position (uv1 in [0,1]^2
// onto the whole viewport); position and normal travel in world space.
layout(location = 0) in vec3 st_position;
layout(location = 1) in vec3 st_normal;
layout(location = 2) in vec2 st_uv1;
uniform mat4 st_model;
uniform mat3 st_normal_matrix;
out vec3 v_world;
out vec3 v_normal;
void main() {
    v_world = (st_model * vec4(st_position, 1.0)).xyz;
    v_normal = st_normal_matrix * st_normal;
    gl_Position = vec4(st_uv1 * 2.0 - 1.0, 0.0, 1.0);
}
