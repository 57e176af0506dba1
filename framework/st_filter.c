// The box pixel filter (st_world_opts.filter): each frame shifts the
// camera by a sub-pixel offset from one of two interleaved, differently
// shifted Halton sequences, and the world accumulates the frames' mean until
// the difference of the two halves says the mean image's NRMSE is below the
// tolerance.
#include "st_world_state.h"
#include <cglm/cglm.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static double radical_inverse(uint32_t k, uint32_t base) {
    double inv = 1.0 / base, f = inv, r = 0;
    for (; k; k /= base, f *= inv)
        r += f * (k % base);
    return r;
}

void st_jitter_offset(uint32_t k, float out[2]) {
    // Even frames: Halton (2, 3) shifted by half a pixel, so k = 0 is the
    // centre. Odd frames: Halton (3, 2) under an irrational toroidal shift
    // (the R2 sequence's step), stratified as well but otherwise unrelated:
    // on the emitter of tests/render/test_filter.c the difference of the two
    // halves predicts the NRMSE of their mean within 0.9-1.3x, where the same
    // Halton (2, 3) points merely shifted for the odd frames gave 0.65-0.85x
    // (their errors correlate) and the R2 sequence converged more slowly.
    uint32_t j = k >> 1;
    double x, y;
    if (!(k & 1))
        x = radical_inverse(j, 2) + 0.5, y = radical_inverse(j, 3) + 0.5;
    else
        x = radical_inverse(j, 3) + 0.5 + 0.7548776662466927,
        y = radical_inverse(j, 2) + 0.5 + 0.5698402909980532;
    out[0] = (float)(x - floor(x) - 0.5);
    out[1] = (float)(y - floor(y) - 0.5);
}

// The camera's matrices for a sample `jitter` pixels right of and below the
// pixel centre: the image shifts the other way in NDC.
static void jitter_matrices(st_world *w) {
    mat4 t = GLM_MAT4_IDENTITY_INIT, proj, view, p, vp, inv;
    t[3][0] = -2.0f * w->jitter[0] / (float)w->cam.width;
    t[3][1] = 2.0f * w->jitter[1] / (float)w->cam.height;
    memcpy(proj, w->cam.proj, sizeof proj);
    memcpy(view, w->cam.view, sizeof view);
    glm_mat4_mul(t, proj, p);
    glm_mat4_mul(p, view, vp);
    glm_mat4_inv(vp, inv);
    memcpy(w->jit_proj, p, sizeof w->jit_proj);
    memcpy(w->jit_vp, vp, sizeof w->jit_vp);
    memcpy(w->jit_ivp, inv, sizeof w->jit_ivp);
}

// Whether every progressive module has converged (true without any): until
// then each frame's image differs, so it replaces the accumulated one.
static bool modules_settled(const st_world *w) {
    for (int i = 0; i < w->num_mods; i++) {
        st_progress p = {0};
        const st_plugin *pl = w->mods[i]->p;
        if (pl->progress && pl->progress(w->mods[i]->self, &p) && !p.converged) return false;
    }
    return true;
}

// The convergence test, at an even frame count n: the even frames' mean A
// and the odd frames' mean B each integrate the pixel with their own
// stratified sequence, so (A - B) / 2 is a sample of the error of the mean
// (A + B) / 2, and E = rms over pixels and channels of (A - B) / 2 over the
// image's mean estimates the NRMSE of the image against the converged one:
// the error the cross-check reports, dominated as it is by whatever pixels
// (a window, a lit silhouette) carry the most of it. E = sqrt(mean(D^2)) /
// mean(S) with D the halves' summed difference and S the summed image, each
// over the pixel's own frame count n_p (its sums' alpha: pixels frozen by
// the adaptive mask keep theirs). The difference also sees the sequences'
// quasi-random convergence, which an iid variance estimate overstates.
static bool accum_error(st_world *w, const st_target *t, double tol, st_err *err) {
    size_t px = (size_t)t->width * t->height, bytes = px * 4 * sizeof(float);
    if (!w->acc_read && !(w->acc_read = malloc(2 * bytes + 2 * px * sizeof(double))))
        return st_fail(err, ST_ERR_RUNTIME, "out of memory reading back %dx%d", t->width,
                       t->height);
    float *sum = w->acc_read, *diff = w->acc_read + px * 4;
    double *e2 = (double *)(w->acc_read + px * 8), *spread = e2 + px; // 32 px bytes in: aligned
    glGetTextureImage(t->color[0], 0, GL_RGBA, GL_FLOAT, (GLsizei)bytes, sum);
    glGetTextureImage(t->color[2], 0, GL_RGBA, GL_FLOAT, (GLsizei)bytes, diff);
    double sum_s = 0, sum_d2 = 0;
    for (size_t p = 0; p < px; p++) {
        double n = sum[4 * p + 3] > 0 ? sum[4 * p + 3] : 1;
        e2[p] = 0;
        for (int c = 0; c < 3; c++)
            sum_s += sum[4 * p + c] / n,
                e2[p] += (double)diff[4 * p + c] * diff[4 * p + c] / (n * n);
        sum_d2 += e2[p];
        // The frames' own spread over the pixel, which a chance agreement
        // of the halves at an edge does not hide: var / n^1.5, the squared
        // error of a stratified mean of a step across the pixel (rms
        // n^-3/4, where the Halton points measure n^-0.9); var / n, the iid
        // bound, kept a fifth of spot_fog's pixels (a fog cone's smooth
        // gradient, whose stratified error falls as 1 / n) shading to the end.
        double sq = 0;
        for (int c = 0; c < 3; c++)
            sq += (double)sum[4 * p + c] * sum[4 * p + c] / (n * n);
        double var = diff[4 * p + 3] / n - sq;
        spread[p] = fmax(e2[p], fmax(var, 0) / (n * sqrt(n)));
    }
    double m = sum_s / (px * 3);
    w->acc_err = sum_s > 0 ? sqrt(sum_d2 / (px * 3)) / m : 0;
    if (!isfinite(w->acc_err)) w->acc_err = INFINITY;
    if (isfinite(w->acc_err) && sum_s > 0) st_filter_mask_update(w, spread, m, tol);
    return st_gl_check("accumulation read back", err);
}

// Adds the frame just rendered to the running sums; the mean becomes the
// camera's current image.
bool st_filter_accumulate(st_world *w, st_err *err) {
    st_camera *c = &w->cam;
    double t0 = st_now_ms();
    int next = w->acc_cur ^ 1;
    st_target_bind(&c->accum[next]);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    st_shader_use(w->accumulate);
    st_shader_texture(w->accumulate, "st_hdr_in", GL_TEXTURE_2D, c->current);
    st_shader_texture(w->accumulate, "st_acc_prev", GL_TEXTURE_2D, c->accum[w->acc_cur].color[0]);
    st_shader_texture(w->accumulate, "st_acc_pdiff", GL_TEXTURE_2D, c->accum[w->acc_cur].color[2]);
    st_shader_texture(w->accumulate, "st_acc_mask", GL_TEXTURE_2D, w->acc_mask);
    st_shader_set_float(w->accumulate, "st_acc_sign", w->acc_n & 1 ? -1.0f : 1.0f);
    st_shader_set_int(w->accumulate, "st_acc_first", w->acc_n == 0);
    st_shader_set_float(w->accumulate, "st_acc_n", (float)(w->acc_n + 1));
    st_draw_fullscreen();
    w->acc_cur = next;
    w->acc_n++;
    c->current = c->accum[next].color[1];
    if (!st_gl_check("accumulate", err)) return false;
    if (!modules_settled(w)) {
        w->acc_n = 0; // the next frame starts again (at the centre)
        w->acc_err = INFINITY;
        st_filter_mask_reset(w);
    } else {
        uint32_t cap = w->opts.filter_max_frames > 0 ? (uint32_t)w->opts.filter_max_frames
                                                     : ST_FILTER_MAX_FRAMES;
        double tol = w->opts.filter_tolerance != 0 ? w->opts.filter_tolerance : ST_FILTER_TOLERANCE;
        if (w->acc_n == 1) w->acc_err = cap == 1 ? 0 : INFINITY, w->acc_below = 0;
        // Even counts only (both halves equal); the last estimate stands between.
        if (w->acc_n % 2 == 0) {
            if (!accum_error(w, &c->accum[next], tol, err)) return false;
            w->acc_below = w->acc_err <= tol ? w->acc_below + 1 : 0;
        }
        // Two estimates in a row within the tolerance, so that a chance
        // agreement of the halves at a few bright pixels does not stop it.
        w->acc_done = w->acc_n >= cap || (w->acc_n >= ST_FILTER_MIN_FRAMES && w->acc_below >= 2);
    }
    st_pass_stats *ps = &w->stats[w->acc_stats];
    ps->runs++;
    ps->ran_last_frame = true;
    if (ps->num_samples < ST_STATS_MAX_SAMPLES) {
        ps->cpu_ms[ps->num_samples] = (float)(st_now_ms() - t0);
        ps->gpu_ms[ps->num_samples] = -1;
        ps->num_samples++;
    }
    return true;
}

bool st_world_read_error(st_world *w, st_image *out, st_err *err) {
    if (w->opts.filter != ST_FILTER_BOX || w->acc_n < 2)
        return st_fail(err, ST_ERR_INPUT,
                       "an error map needs a box still of at least 2 frames (%u accumulated)",
                       w->opts.filter == ST_FILTER_BOX ? w->acc_n : 0);
    int W_ = w->cam.width, H = w->cam.height;
    float *rgba = malloc((size_t)W_ * H * 4 * sizeof(float));
    if (!rgba) return st_fail(err, ST_ERR_RUNTIME, "out of memory reading %dx%d", W_, H);
    // The halves' summed difference D: (A - B) / 2 = D / n at an even n.
    bool ok = st_target_read(&w->cam.accum[w->acc_cur], 2, rgba, err) &&
              st_image_alloc(out, W_, H, 3, err);
    for (size_t k = 0; ok && k < (size_t)W_ * H; k++)
        for (int c = 0; c < 3; c++)
            out->data[3 * k + c] = fabsf(rgba[4 * k + c]) / (float)w->acc_n;
    free(rgba);
    return ok;
}

st_pixel_filter st_world_filter(const st_world *w) {
    return w->opts.filter;
}

bool st_filter_begin(st_world *w) {
    unsigned outside = w->changes;
    for (int m = 0; m < w->num_mods; m++)
        if (w->mods[m]->params_dirty) outside |= ST_CHANGE_PARAMS;
    if (outside) w->acc_n = 0, w->acc_done = false, w->acc_err = INFINITY;
    if (w->acc_n == 0) st_filter_mask_reset(w);
    if (w->acc_done) return false;
    // A new accumulation: no pass may take what is pending for a jitter only.
    if (w->acc_n == 0)
        for (int i = 0; i < w->num_slots; i++)
            w->slots[i].pending &= ~ST_CHANGE_JITTER;
    // Only what depends on the camera redoes a jittered frame; the frames
    // after the first say that the move was a jitter (ST_CHANGE_JITTER).
    float j[2];
    st_jitter_offset(w->acc_n, j);
    if (j[0] != w->jitter[0] || j[1] != w->jitter[1])
        w->changes |= ST_CHANGE_CAMERA | (w->acc_n > 0 ? ST_CHANGE_JITTER : 0);
    memcpy(w->jitter, j, sizeof j);
    jitter_matrices(w);
    return true;
}
