// Anti-aliased disc: coverage falls from 1 to 0 over one texel at the rim, so
// the disc's summed radiance (pi r^2 L) does not jump when it moves by a
// fraction of a texel. Blended over the emitters and sky behind it.
uniform vec2 u_disc_center_px;
uniform float u_disc_radius_px;
uniform vec3 u_disc_radiance;
layout(location = 0) out vec4 o_color;
void main() {
    float d = length(gl_FragCoord.xy - u_disc_center_px);
    o_color = vec4(clamp(u_disc_radiance, vec3(0.0), vec3(1e30)), clamp(u_disc_radius_px - d + 0.5, 0.0, 1.0));
}
