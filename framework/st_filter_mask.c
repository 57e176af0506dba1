// The box filter's adaptive mask: once a still has accumulated
// ST_FILTER_MASK_START frames, a pixel whose estimated error, and its
// neighbours', is far below the tolerance (ST_FILTER_MASK_SHARE of it, in
// rms per pixel over the image's mean) stops accumulating: it keeps its
// frames' sums and its error estimate, and the frames after that shade only
// the pixels still accumulating (a depth prefill of 0 at the frozen ones
// fails the regular pass's and the post passes' depth tests, so llvmpipe
// skips their fragment work). A frozen pixel's mean is that of its own
// frames, still a stratified estimate of its square; the image's estimate
// sums every pixel's, frozen or not. On spot_fog at 128x128, 97 % of the
// squared error sits in 1 % of the pixels (edges, the spot's apex).
#include "st_world_state.h"
#include <stdlib.h>
#include <string.h>

bool st_filter_mask_init(st_world *w, st_err *err) {
    int px = w->cam.width * w->cam.height;
    st_filter_mask_free(w);
    w->acc_frozen = calloc((size_t)px, 1);
    if (!w->acc_frozen)
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for a %dx%d mask", w->cam.width,
                       w->cam.height);
    glCreateTextures(GL_TEXTURE_2D, 1, &w->acc_mask);
    glTextureStorage2D(w->acc_mask, 1, GL_R8, w->cam.width, w->cam.height);
    glTextureParameteri(w->acc_mask, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(w->acc_mask, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glObjectLabel(GL_TEXTURE, w->acc_mask, -1, "camera.still_mask");
    w->acc_num_frozen = -1; // the texture's contents are undefined: cleared on reset
    st_filter_mask_reset(w);
    return st_gl_check("still mask", err);
}

void st_filter_mask_free(st_world *w) {
    if (w->acc_mask) glDeleteTextures(1, &w->acc_mask);
    w->acc_mask = 0;
    free(w->acc_frozen);
    w->acc_frozen = NULL;
    w->acc_num_frozen = 0;
}

static void upload(st_world *w) {
    glTextureSubImage2D(w->acc_mask, 0, 0, 0, w->cam.width, w->cam.height, GL_RED, GL_UNSIGNED_BYTE,
                        w->acc_frozen);
}

void st_filter_mask_reset(st_world *w) {
    if (!w->acc_frozen || w->acc_num_frozen == 0) return;
    memset(w->acc_frozen, 0, (size_t)w->cam.width * w->cam.height);
    w->acc_num_frozen = 0;
    upload(w);
}

bool st_filter_masked(const st_world *w) {
    return w->opts.filter == ST_FILTER_BOX && w->acc_n > 0 && w->acc_num_frozen > 0 &&
           w->acc_mask_ok;
}

// After the frame's culling: frozen pixels may be skipped only if every
// module pass that runs and reads a camera image is ST_PASS_PIXEL_LOCAL.
void st_filter_mask_gate(st_world *w) {
    static const char *const camera[] = {"hdr", "gbuffer", "albedo", "depth"};
    st_resset cam = {{0}};
    for (int r = 0; r < w->num_res && r < MAX_RESOURCES; r++)
        for (int k = 0; k < 4; k++)
            if (!strcmp(w->res[r], camera[k])) cam.bits[r / 64] |= 1ull << (r % 64);
    w->acc_mask_ok = true;
    for (int i = 0; i < w->num_slots; i++) {
        const st_slot *s = &w->slots[i];
        if (s->mod && s->needed && s->live && !(s->info.flags & ST_PASS_PIXEL_LOCAL) &&
            st_resset_meet(&s->reads, &cam))
            w->acc_mask_ok = false;
    }
}

// At an even count n >= ST_FILTER_MASK_START: e2[p] is the larger of the
// pixel's squared error estimate (the halves') and its frames' variance /
// n^1.5 (st_filter.c), each summed over its channels; m the image's mean.
// Freezes the pixels whose 3x3 neighbourhood's largest e2 is within
// 3 (share tol m)^2. The variance, because at an edge the halves' counts of
// covered samples often agree by chance (both quantised alike) while the
// mean is still off: the emitter of tests/render/test_filter.c froze its
// edges at 32 frames and stopped at an NRMSE of 0.030 against an estimate of
// 0.0098. The stratified rate of a step overstates the Halton mean's error
// at an edge (n^-0.9) and in smooth pixels (1 / n), so a frozen pixel errs
// on the safe side; the neighbourhood, for an edge that only grazes a pixel.
void st_filter_mask_update(st_world *w, const double *e2, double m, double tol) {
    if (!w->acc_frozen || w->opts.filter_tolerance < 0 || w->acc_n < ST_FILTER_MASK_START) return;
    int W_ = w->cam.width, H = w->cam.height, added = 0;
    double lim = 3 * (ST_FILTER_MASK_SHARE * tol * m) * (ST_FILTER_MASK_SHARE * tol * m);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W_; x++) {
            if (w->acc_frozen[y * W_ + x]) continue;
            double mx = 0;
            for (int b = y > 0 ? y - 1 : 0; b <= y + 1 && b < H; b++)
                for (int a = x > 0 ? x - 1 : 0; a <= x + 1 && a < W_; a++)
                    mx = e2[b * W_ + a] > mx ? e2[b * W_ + a] : mx;
            if (mx <= lim) w->acc_frozen[y * W_ + x] = 1, added++;
        }
    if (!added) return;
    w->acc_num_frozen += added;
    upload(w);
}

// Depth 0 where frozen, after the regular pass's clear.
void st_filter_mask_prefill(st_world *w) {
    if (!st_filter_masked(w)) return;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthRangef(0, 0);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    st_shader_use(w->acc_prefill);
    st_shader_texture(w->acc_prefill, "st_acc_mask", GL_TEXTURE_2D, w->acc_mask);
    st_draw_fullscreen();
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthRangef(0, 1);
    glDepthFunc(GL_LESS);
}

// A fullscreen post pass onto the image (post target t) shades only the
// pixels still accumulating: the scene's depth, attached for the pass,
// holds 0 where frozen, and the pass's fragments are at depth 0.
void st_filter_mask_post(st_world *w, st_target *t, bool on) {
    if (on) {
        glNamedFramebufferTexture(t->fbo, GL_DEPTH_ATTACHMENT, w->cam.scene.depth, 0);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_FALSE);
        glDepthRangef(0, 0);
    } else {
        glDepthRangef(0, 1);
        glDepthMask(GL_TRUE);
        glDisable(GL_DEPTH_TEST);
        glNamedFramebufferTexture(t->fbo, GL_DEPTH_ATTACHMENT, 0, 0);
    }
}
