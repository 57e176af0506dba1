// Shadow pass: world position to the cube face's clip space.
layout(location = 0) in vec3 st_position;
uniform mat4 st_model;
uniform mat4 u_view_proj;
out vec3 v_world;
void main() {
    vec4 wp = st_model * vec4(st_position, 1.0);
    v_world = wp.xyz;
    gl_Position = u_view_proj * wp;
}
