// The box filter's adaptive mask (framework/st_filter_mask.c): writes depth 0
// (the world sets the depth range to 0) where a pixel of a converging still
// is frozen, so that the regular pass and the post passes, whose depth tests
// then fail there, shade only the pixels still accumulating.
uniform sampler2D st_acc_mask; // R8: 1 frozen
void main() {
    if (texelFetch(st_acc_mask, ivec2(gl_FragCoord.xy), 0).r == 0.0) discard;
}
