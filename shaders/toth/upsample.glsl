// toth: the depth-aware upsampling of the march (compose and edges passes):
// the bilinear taps that show the pixel's own surface, else the tap nearest in
// distance, so shafts do not bleed across silhouettes; and whether the taps
// disagree so much that the pixel's own ray must be marched (`spread`).
// Compose and keep reconstruct kinks of the visible fraction from the 4 x 4
// taps around the pixel where all four bilinear taps show its surface
// (upsample_kink).
#ifndef TOTH_UPSAMPLE_GLSL
#define TOTH_UPSAMPLE_GLSL
#include "toth/common.glsl"
uniform sampler2D st_gbuffer;
uniform sampler2D toth_inscatter_tex;
uniform float toth_refine; // fraction spread over the taps above which a pixel is marched
uniform int toth_refine_taps; // fewer taps on the pixel's surface than this: marched
uniform sampler2D toth_refined_tex; // the edges pass's fractions (-1: not marched there)
#include "toth/kink.glsl" // toth_refine_kink: the edges pass also marched bent blocks

#ifndef TOTH_EDGES_SELECT
uniform float toth_upsample_kink; // second difference above which a kink is reconstructed (0: off)

// The visible fraction at x in [0, 1] between taps v0 (at 0) and v1 (at 1),
// with their outer neighbours vm (at -1) and v2 (at 2). The fraction is
// piecewise linear with kinks where a view ray starts or stops touching a
// shaft; one kink at c between two lines gives second differences
// a = (sR - sL)(1 - c) at 0 and b = (sR - sL) c at 1, of one sign. The left
// line extended is linear interpolation minus x a, the right one minus
// (1 - x) b; they meet at c = b / (a + b), so the kink is the smaller of the
// two corrections (Harten's subcell resolution). Exact for one kink anywhere
// in [-1, 2]; where the signs differ (an inflection) or both differences are
// small (smooth curvature, for which two lines are worse than one), or where
// an outer tap is unusable (`on` false), linear.
vec4 toth_kink_1d(vec4 vm, vec4 v0, vec4 v1, vec4 v2, float x, bool on) {
    vec4 a = vm - 2.0 * v0 + v1, b = v0 - 2.0 * v1 + v2;
    vec4 bend = sign(a) * min(x * abs(a), (1.0 - x) * abs(b));
    vec4 k = step(0.0, a * b) * step(toth_upsample_kink, max(abs(a), abs(b)));
    return mix(v0, v1, x) - (on ? k * bend : vec4(0.0));
}

// The 4 x 4 march texels around p (b - 1 .. b + 2), its rows reconstructed
// at fr.x, then that column at fr.y: exact for the minimum or maximum of two
// planes (a straight kink at any angle). The inner four show p's surface
// (the caller checks); an outer tap counts where it is continuous with the
// tap beside it toward the centre (toth_continuous; a chain, so a floor
// seen at a grazing angle, whose distance changes by more than
// edge_tolerance over 3 texels, still counts), and a row or the column with
// a tap that is not (a silhouette beside the kink) or beyond the image is
// interpolated linearly. Normals may differ: at a crease the ray length,
// and so the fraction, bends, one more kink (godrays_hidden_hole's shaft
// beside the floor's crease: rmse 5.3e-5 -> 3.4e-5 at samples=256 quarter
// against requiring toth_similar).
vec4 toth_upsample_kinked(ivec2 b, vec2 fr) {
    ivec2 size = textureSize(toth_inscatter_tex, 0);
    vec4 t[16], gt[16];
    bool in_image[16];
    for (int k = 0; k < 16; k++) {
        ivec2 q = b + ivec2(k & 3, k >> 2) - 1;
        in_image[k] = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
        q = clamp(q, ivec2(0), size - 1);
        t[k] = texelFetch(toth_inscatter_tex, q, 0);
        gt[k] = texelFetch(st_gbuffer, toth_full_pixel(q), 0);
    }
    // The outer rows' inner taps against the inner rows' (the column's taps).
    bool column = in_image[1] && in_image[2] && in_image[13] && in_image[14] &&
                  toth_continuous(gt[1], gt[5]) && toth_continuous(gt[2], gt[6]) &&
                  toth_continuous(gt[13], gt[9]) && toth_continuous(gt[14], gt[10]);
    vec4 r[4];
    for (int j = 0; j < 4; j++) {
        int k = 4 * j;
        bool row = in_image[k] && in_image[k + 3] && toth_continuous(gt[k], gt[k + 1]) &&
                   toth_continuous(gt[k + 3], gt[k + 2]) && (column || (j == 1 || j == 2));
        r[j] = toth_kink_1d(t[k], t[k + 1], t[k + 2], t[k + 3], fr.x, row);
    }
    return toth_kink_1d(r[0], r[1], r[2], r[3], fr.y, column);
}
#endif

// spread: how much the taps that were mixed differ (max - min over the
// channels), 1 when none showed the pixel's surface.
vec4 toth_upsample(ivec2 p, vec4 g, out float spread) {
    ivec2 size = textureSize(toth_inscatter_tex, 0);
    spread = 0.0;
    if (toth_scale <= 1) return texelFetch(toth_inscatter_tex, p, 0);
    vec4 lo = vec4(1e30), hi = vec4(-1e30), lo_all = vec4(1e30), hi_all = vec4(-1e30);
    // March pixel k traces full pixel k * scale + (scale - 1) / 2.
    vec2 f = (vec2(p) - float((toth_scale - 1) / 2)) / float(toth_scale);
    ivec2 b = ivec2(floor(f));
    vec2 fr = f - vec2(b);
    vec4 sum = vec4(0.0);
    float wsum = 0.0, best = 1e30;
    int used = 0;
    vec4 nearest = vec4(0.0);
    float s = toth_ray_length(g, p);
    for (int k = 0; k < 4; k++) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(b + o, ivec2(0), size - 1);
        vec4 gq = texelFetch(st_gbuffer, toth_full_pixel(q), 0);
        vec4 v = texelFetch(toth_inscatter_tex, q, 0);
        float bil = (o.x == 1 ? fr.x : 1.0 - fr.x) * (o.y == 1 ? fr.y : 1.0 - fr.y);
        bool same = toth_similar(g, gq);
        if (same) {
            sum += (bil + 1e-3) * v;
            wsum += bil + 1e-3;
        }
        float diff = abs(toth_ray_length(gq, toth_full_pixel(q)) - s) + ((g.w < 0.0) != (gq.w < 0.0) ? 1e20 : 0.0);
        if (diff < best) {
            best = diff;
            nearest = v;
        }
#ifdef TOTH_EDGES_SELECT
        // A tap clamped at the border extrapolates the texel beside it as a
        // constant, exact only where the fraction is: the select step's
        // settled test below judges it by the texel mirrored inward (the
        // next one along the clamped axis), as if it were the tap.
        ivec2 m = toth_mirror(b + o, size);
        if (m != q) {
            gq = texelFetch(st_gbuffer, toth_full_pixel(m), 0);
            v = texelFetch(toth_inscatter_tex, m, 0);
            same = toth_similar(g, gq);
        }
#endif
        lo_all = min(lo_all, v);
        hi_all = max(hi_all, v);
        if (same) {
            used++;
            lo = min(lo, v);
            hi = max(hi, v);
        }
    }
    vec4 d = hi - lo;
    // Taps that show another surface (a silhouette or a crease), or that are
    // clamped at the image border, leave the others as a one-sided guess
    // that can agree with itself: below toth_refine_taps usable taps, or with
    // a clamped tap, count that as full disagreement, so such pixels march
    // their own ray too -- unless one shows the pixel's surface and all four
    // (a clamped one mirrored) see exactly the same fraction (a crease or silhouette
    // wholly lit or wholly in shadow: on the window and hole scenes at 600^2
    // this takes 40% off compose's time; relaxing it further, to taps that agree
    // within 0.01, puts pixels beside a crease 8% off in test_toth_sun_shadow).
    bool clamped = any(lessThan(b, ivec2(0))) || any(greaterThan(b + 1, size - 1));
    bool settled = used > 0 && all(equal(hi_all, lo_all));
#ifndef TOTH_EDGES_SELECT
    // Compose and keep need no mirrored taps: a border pixel reads
    // toth.refined, which holds its own ray where the select step listed it.
    settled = settled && !clamped;
#endif
    spread = used >= toth_refine_taps && !clamped ? max(max(d.x, d.y), max(d.z, d.w)) : settled ? 0.0 : 1.0;
#ifndef TOTH_EDGES_SELECT
    // Compose and keep: a kink between the taps reconstructed (upsample_kink).
    if (toth_upsample_kink > 0.0 && used == 4 && !clamped) return toth_upsample_kinked(b, fr);
#endif
    return wsum > 0.0 ? sum / wsum : nearest;
}

// The fraction compose uses at p (and the keep pass keeps): the upsampled
// one, unless the taps disagree (a shaft's edge, a silhouette) or bent
// blocks were marched too, and the edges pass marched this pixel's own ray.
vec4 toth_refined(ivec2 p, vec4 up, float spread) {
    if (spread > toth_refine || (toth_refine_kink > 0.0 && toth_scale > 1)) {
        vec4 r = texelFetch(toth_refined_tex, p, 0);
        if (r.x >= 0.0) return r;
    }
    return up;
}
#endif
