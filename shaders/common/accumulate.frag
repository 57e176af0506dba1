// The box pixel filter's accumulation (st_filter.c): adds this frame's
// radiance to the running sums and writes their mean. Sums: RGB and the
// pixel's frame count (A), and the difference of the two interleaved halves, the even frames' sum
// minus the odd frames' (the convergence test's image error estimate), with
// the sum of the frames' squared R, G, B in its A (the adaptive mask's
// spread).
uniform sampler2D st_hdr_in;    // this frame, sampled at its jittered offset
uniform sampler2D st_acc_prev;  // the sums so far (ignored for the first frame)
uniform sampler2D st_acc_pdiff; // the halves' difference so far (likewise)
uniform sampler2D st_acc_mask;  // R8, 1: the pixel stopped (st_filter_mask.c), its sums stay
uniform int st_acc_first;       // 1: this frame starts the sums
uniform float st_acc_n;         // frames in the sums including this one
uniform float st_acc_sign;      // +1: an even frame, -1: an odd one
layout(location = 0) out vec4 o_sum;
layout(location = 1) out vec4 o_mean;
layout(location = 2) out vec4 o_diff;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 c = texelFetch(st_hdr_in, p, 0).rgb;
    bool first = st_acc_first != 0;
    vec4 s = first ? vec4(0.0) : texelFetch(st_acc_prev, p, 0);
    vec4 d = first ? vec4(0.0) : texelFetch(st_acc_pdiff, p, 0);
    if (!first && texelFetch(st_acc_mask, p, 0).r > 0.0) {
        o_sum = s;
        o_diff = d;
    } else {
        // Every pixel still accumulating has all st_acc_n frames.
        o_sum = vec4(s.rgb + c, st_acc_n);
        o_diff = vec4(d.rgb + st_acc_sign * c, d.a + dot(c, c));
    }
    o_mean = vec4(o_sum.rgb / o_sum.a, 1.0);
}
