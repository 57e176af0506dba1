// toth pass 1 as a compute dispatch of 8 x 8 texel groups (toth.c picks it
// for a march of fewer than 4 llvmpipe tiles, march.frag otherwise):
// llvmpipe hands a draw's 64 x 64 pixel tiles to its threads, so the 80 x 60
// quarter-resolution march of a 320x240 image is two tiles of 3840 and 960
// rays and one thread waits for the other; work groups spread evenly. A
// dispatch costs llvmpipe more per texel (~1.3x here), so larger marches
// are drawn.
#include "toth/march_texel.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) uniform writeonly image2D toth_march_img;

void main() {
    ivec2 lp = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(lp, imageSize(toth_march_img)))) return;
    imageStore(toth_march_img, lp, toth_march_texel(lp));
}
