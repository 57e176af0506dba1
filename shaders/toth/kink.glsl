// toth's edges pass: where the visible fraction bends at a march texel
// (refine_kink), bilinear upsampling cuts the ridge or fills the valley
// (godrays_hidden_hole: a column of pixels 1.5% low under the hole at half
// resolution), so the block's pixels march their own rays. The includer
// declares toth_inscatter_tex (the march or gather output).
#ifndef TOTH_KINK_GLSL
#define TOTH_KINK_GLSL
uniform float toth_refine_kink; // second difference above which a block is marched (0: off)

// Block k (its march texel): the largest second difference of the fraction
// along its row or column, any channel, against toth_refine_kink.
bool toth_kinked(ivec2 k) {
    if (!(toth_refine_kink > 0.0)) return false;
    ivec2 size = textureSize(toth_inscatter_tex, 0);
    if (any(lessThan(k, ivec2(1))) || any(greaterThan(k, size - 2))) return false;
    vec4 c = 2.0 * texelFetch(toth_inscatter_tex, k, 0);
    vec4 dx = abs(texelFetch(toth_inscatter_tex, k - ivec2(1, 0), 0) + texelFetch(toth_inscatter_tex, k + ivec2(1, 0), 0) - c);
    vec4 dy = abs(texelFetch(toth_inscatter_tex, k - ivec2(0, 1), 0) + texelFetch(toth_inscatter_tex, k + ivec2(0, 1), 0) - c);
    vec4 m = max(dx, dy);
    return max(max(m.x, m.y), max(m.z, m.w)) > toth_refine_kink;
}
#endif
