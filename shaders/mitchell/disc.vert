// Mitchell occlusion pre-pass: the light's emitting region as a screen-facing
// disc. A quad around the projected centre (from gl_VertexID, 4 vertices as a
// strip) at the depth of the sphere's front; mitchell.c computes the numbers.
uniform vec2 u_disc_center; // NDC
uniform vec2 u_disc_extent; // NDC half size of the quad (radius plus a texel)
uniform float u_disc_depth; // NDC z
void main() {
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
    gl_Position = vec4(u_disc_center + corner * u_disc_extent, u_disc_depth, 1.0);
}
