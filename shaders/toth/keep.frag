// toth, reuse=on: the first frame of a box-filtered still keeps the visible
// fraction compose uses at every pixel (upsampled, or the edges pass's own
// ray: the same rule as compose.frag), for the jittered frames that follow
// (toth/reuse.glsl). The module copies the gbuffer beside it.
#include "common/uniforms.glsl"
#include "toth/common.glsl"
#include "toth/upsample.glsl"
layout(location = 0) out vec4 o_fraction;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float spread = 0.0;
    vec4 up = toth_upsample(p, texelFetch(st_gbuffer, p, 0), spread);
    o_fraction = toth_refined(p, up, spread);
}
