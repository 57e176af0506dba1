// height_fog, pass "fog": L = L_surface T + radiance (1 - T), T = e^(-tau),
// tau from the compute pass (its target height_fog.tau, which the plugin
// exports as the uniform height_fog_tau); pixels without a surface keep L.
uniform sampler2D st_hdr_in;
uniform sampler2D height_fog_tau;
uniform float u_radiance;
layout(location = 0) out vec4 o_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 L = texelFetch(st_hdr_in, px, 0).rgb;
    float tau = texelFetch(height_fog_tau, px, 0).r;
    float T = exp(-tau);
    o_color = vec4(tau < 0.0 ? L : L * T + u_radiance * (1.0 - T), 1.0);
}
