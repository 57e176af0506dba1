// toth, reuse=on: the first frame of a box-filtered still keeps the visible
// fraction compose uses at every pixel (upsampled, or the edges pass's own
// ray: the same rule as compose.frag), for the jittered frames that follow
// (toth/reuse.glsl). The module copies the gbuffer beside it.
#include "common/uniforms.glsl"
#include "toth/common.glsl"
#include "toth/upsample.glsl"
uniform sampler2D toth_refined_tex;
uniform float toth_refine_kink;
layout(location = 0) out vec4 o_fraction;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float spread = 0.0;
    vec4 frac = toth_upsample(p, texelFetch(st_gbuffer, p, 0), spread);
    if (spread > toth_refine || (toth_refine_kink > 0.0 && toth_scale > 1)) {
        vec4 r = texelFetch(toth_refined_tex, p, 0);
        if (r.x >= 0.0) frac = r;
    }
    o_fraction = frac;
}
