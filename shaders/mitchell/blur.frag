// Mitchell (GPU Gems 3, ch. 13; thesis listing A.4): radial blur of the
// occlusion image from the pixel toward the light in n steps of
// (pixel - light) / (n density), tap i weighted decay^i weight, the pixel's
// own tap unweighted; exposure times the sum (times the off-screen fade) is
// added to the scene image. Coordinates are texture coordinates of the
// screen, (0,0) bottom left; taps outside the screen read 0 (border).
#include "common/uniforms.glsl"
uniform sampler2D st_hdr_in;
uniform sampler2D u_occlusion;
uniform vec2 u_out_size; // target size in pixels
uniform vec2 u_light_uv;
uniform vec2 u_shift; // a box still's jittered frame: its sample in the occlusion image's frame
uniform int u_samples;
uniform float u_density, u_decay, u_weight, u_exposure, u_fade;
layout(location = 0) out vec4 o_color;

void main() {
    // Pixel centres exactly, so a plain C loop can reproduce every tap.
    // A jittered frame of a still reads its first frame's occlusion image:
    // the sample and the light both shift by the offsets' difference.
    vec2 uv = gl_FragCoord.xy / u_out_size + u_shift;
    vec2 delta = (uv - (u_light_uv + u_shift)) / (float(u_samples) * u_density);
    vec3 sum = texture(u_occlusion, uv).rgb;
    float decay_i = 1.0;
    vec2 p = uv;
    for (int i = 0; i < u_samples; i++) {
        p -= delta;
        sum += texture(u_occlusion, p).rgb * (decay_i * u_weight);
        decay_i *= u_decay;
    }
    // Finite inputs never give NaN here (no inf - inf); clamp away overflow.
    sum = min(sum, vec3(1e30));
    vec3 hdr = texelFetch(st_hdr_in, ivec2(gl_FragCoord.xy), 0).rgb;
    o_color = vec4(min(hdr + sum * (u_exposure * u_fade), vec3(3e38)), 1.0);
}
