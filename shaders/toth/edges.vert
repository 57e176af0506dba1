// toth's edges pass (equiangular below full resolution): one point per
// scale x scale block of full-resolution pixels, kept only where a pixel of
// the block may have to march its own ray (toth/upsample.glsl's rule); the
// rest are moved outside the clip volume, so no fragment of theirs runs.
// A block is skipped when no pixel of it would be marched by that rule,
// evaluated here on its taps -- the 3 x 3 march texels around the block,
// those beyond the image border mirrored inward as toth_upsample judges them.
#include "common/uniforms.glsl"
#include "toth/common.glsl"
uniform sampler2D st_gbuffer;
uniform sampler2D toth_inscatter_tex;
uniform int toth_blocks_x; // blocks per image row
uniform float toth_refine;
uniform int toth_refine_taps;
#include "toth/kink.glsl"

bool toth_block_settled(ivec2 k) {
    ivec2 size = textureSize(toth_inscatter_tex, 0);
    vec4 vt[9], gt[9];
    for (int i = 0; i < 9; i++) {
        ivec2 q = toth_mirror(k - 1 + ivec2(i % 3, i / 3), size);
        vt[i] = texelFetch(toth_inscatter_tex, q, 0);
        gt[i] = texelFetch(st_gbuffer, toth_full_pixel(q), 0);
    }
    for (int j = 0; j < toth_scale * toth_scale; j++) {
        ivec2 p = k * toth_scale + ivec2(j % toth_scale, j / toth_scale);
        if (any(greaterThanEqual(p, ivec2(st_resolution)))) continue;
        vec4 g = texelFetch(st_gbuffer, p, 0);
        // The taps of p, as toth_upsample finds them (b - k + 1 in {0, 1} per axis).
        ivec2 b = ivec2(floor((vec2(p) - float((toth_scale - 1) / 2)) / float(toth_scale))) - k + 1;
        bool clamped = any(lessThan(b + k - 1, ivec2(0))) || any(greaterThan(b + k, size - 1));
        vec4 lo = vec4(1e30), hi = vec4(-1e30), lo_all = vec4(1e30), hi_all = vec4(-1e30);
        int used = 0;
        for (int o = 0; o < 4; o++) {
            int i = b.x + (o & 1) + 3 * (b.y + (o >> 1));
            lo_all = min(lo_all, vt[i]);
            hi_all = max(hi_all, vt[i]);
            if (toth_similar(g, gt[i])) {
                used++;
                lo = min(lo, vt[i]);
                hi = max(hi, vt[i]);
            }
        }
        vec4 d = hi - lo;
        bool settled = used > 0 && all(equal(hi_all, lo_all));
        float spread = used >= toth_refine_taps && !clamped ? max(max(d.x, d.y), max(d.z, d.w)) : settled ? 0.0 : 1.0;
        if (spread > toth_refine) return false;
    }
    return true;
}

void main() {
    ivec2 k = ivec2(gl_VertexID % toth_blocks_x, gl_VertexID / toth_blocks_x);
    vec2 centre = (vec2(k) + 0.5) * float(toth_scale) / st_resolution * 2.0 - 1.0;
    gl_Position = toth_block_settled(k) && !toth_kinked(k) ? vec4(3.0, 3.0, 3.0, 1.0) : vec4(centre, 0.0, 1.0);
}
