// toth's edges pass, select step: in the blocks edges.vert keeps, each pixel
// whose upsampling taps disagree (toth/upsample.glsl) or whose block is bent
// (toth/kink.glsl) is appended to the list (toth/edges_list.glsl) that the
// march step marches at full resolution, one densely packed fragment per
// pixel. Nothing is written here: toth.refined stays at its cleared -1,
// which compose reads as "upsample", where no ray is marched.
#include "common/uniforms.glsl"
#include "toth/common.glsl"
#define TOTH_EDGES_SELECT 1 // the border judged with mirrored taps (upsample.glsl)
#include "toth/upsample.glsl"
#include "toth/kink.glsl"
#include "toth/edges_list.glsl"

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 g = texelFetch(st_gbuffer, p, 0);
    float spread = 0.0;
    toth_upsample(p, g, spread);
    if (spread > toth_refine || toth_kinked(p / toth_scale))
        toth_edges_list[atomicAdd(toth_edges_count, 1u)] = uint(p.x) | (uint(p.y) << 16);
}
