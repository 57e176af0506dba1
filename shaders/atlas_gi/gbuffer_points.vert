// G-buffer atlas, conservative part: one point per texel that no triangle's
// rasterization reaches (its centre lies outside every triangle), at the
// texel centre, with the world attributes of the texel's covered part.
layout(location = 0) in vec2 a_texel;
layout(location = 1) in vec3 a_world;
layout(location = 2) in vec3 a_normal;
layout(location = 3) in vec3 a_albedo;
layout(location = 4) in vec3 a_emission;
uniform vec2 ag_size;
out vec3 v_world;
out vec3 v_normal;
flat out vec3 v_albedo;
flat out vec3 v_emission;
void main() {
    v_world = a_world;
    v_normal = a_normal;
    v_albedo = a_albedo;
    v_emission = a_emission;
    gl_Position = vec4((a_texel + 0.5) / ag_size * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;
}
