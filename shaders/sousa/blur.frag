// Sousa sun shafts (CryEngine 2, GDC 2008; thesis listing A.7): from the
// pixel toward the light in fixed steps of u_step (texture coordinates), at
// most u_taps taps, stopping at the light; the sum times brightness. Run three
// times with steps TAPS^-1, TAPS^-2, TAPS^-3, each pass reading the last one's
// output (interleaved sampling). With SOUSA_COMPOSE the last pass adds the
// result, tinted by the light and faded off screen, to the scene image.
// Taps outside the screen read 0 (border).
#include "common/uniforms.glsl"
uniform sampler2D u_src;
uniform vec2 u_out_size; // target size in pixels
uniform vec2 u_light_uv;
uniform int u_taps;
uniform float u_step, u_brightness;
#ifdef SOUSA_COMPOSE
uniform sampler2D st_hdr_in;
uniform vec3 u_color;
uniform float u_fade;
#endif
layout(location = 0) out vec4 o_color;

float sousa_blur(vec2 pixel) {
    vec2 v = u_light_uv - pixel;
    float l = length(v);
    // At the light itself (l = 0) there is no direction: only the pixel's tap.
    vec2 stp = l > 0.0 ? v * (u_step / l) : vec2(0.0);
    float max_steps = l / u_step;
    float sum = 0.0;
    vec2 p = pixel;
    for (int i = 0; i < u_taps; i++) {
        // The thesis stops at i >= l/step; the pixel's own tap always counts
        // so the light's pixel is not a black hole in the shafts.
        if (i > 0 && float(i) >= max_steps) break;
        sum += texture(u_src, p).r;
        p += stp;
    }
    return min(sum * u_brightness, 1e30);
}

void main() {
    vec2 uv = gl_FragCoord.xy / u_out_size;
    float s = sousa_blur(uv);
#ifdef SOUSA_COMPOSE
    vec3 hdr = texelFetch(st_hdr_in, ivec2(gl_FragCoord.xy), 0).rgb;
    o_color = vec4(min(hdr + u_color * (s * u_fade), vec3(3e38)), 1.0);
#else
    o_color = vec4(s, 0.0, 0.0, 1.0);
#endif
}
