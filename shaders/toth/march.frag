// toth pass 1 drawn over the march target (toth.c: a march of 4 llvmpipe
// tiles or more; smaller ones are dispatched, march.comp).
#include "toth/march_texel.glsl"
layout(location = 0) out vec4 o_march;

void main() { o_march = toth_march_texel(ivec2(gl_FragCoord.xy)); }
