// The box pixel filter's accumulation (st_world.c): adds this frame's
// radiance to the running sums and writes their mean. Sums: RGB, and in A the
// sum of the squared luminance (mean of R, G, B) for the convergence test.
uniform sampler2D st_hdr_in;   // this frame, sampled at its jittered offset
uniform sampler2D st_acc_prev; // the sums so far (ignored for the first frame)
uniform int st_acc_first;      // 1: this frame starts the sums
uniform float st_acc_n;        // frames in the sums including this one
layout(location = 0) out vec4 o_sum;
layout(location = 1) out vec4 o_mean;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 c = texelFetch(st_hdr_in, p, 0).rgb;
    float y = (c.r + c.g + c.b) / 3.0;
    vec4 s = st_acc_first != 0 ? vec4(0.0) : texelFetch(st_acc_prev, p, 0);
    o_sum = s + vec4(c, y * y);
    o_mean = vec4(o_sum.rgb / st_acc_n, 1.0);
}
