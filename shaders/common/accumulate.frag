// The box pixel filter's accumulation (st_filter.c): adds this frame's
// radiance to the running sums and writes their mean. Sums: RGB (A unused),
// and the difference of the two interleaved halves, the even frames' sum
// minus the odd frames' (the convergence test's image error estimate).
uniform sampler2D st_hdr_in;    // this frame, sampled at its jittered offset
uniform sampler2D st_acc_prev;  // the sums so far (ignored for the first frame)
uniform sampler2D st_acc_pdiff; // the halves' difference so far (likewise)
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
    vec3 s = first ? vec3(0.0) : texelFetch(st_acc_prev, p, 0).rgb;
    vec3 d = first ? vec3(0.0) : texelFetch(st_acc_pdiff, p, 0).rgb;
    o_sum = vec4(s + c, 0.0);
    o_diff = vec4(d + st_acc_sign * c, 0.0);
    o_mean = vec4(o_sum.rgb / st_acc_n, 1.0);
}
