// The box pixel filter (st_world_opts.filter): each frame shifts the
// camera by a Halton sub-pixel offset and the world accumulates the frames'
// mean until its relative standard error is below the tolerance.
#include "st_world_priv.h"
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
    double x = radical_inverse(k, 2) + 0.5, y = radical_inverse(k, 3) + 0.5;
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

// The convergence test: the relative standard error of the mean image,
// E = sqrt(mean over pixels of (s_p^2 / n) / (m_p^2 + M^2)), with m_p and
// s_p^2 the mean and sample variance of pixel p's luminance over n frames and
// M the image's mean luminance: atlas_gi's rule for its gather (the RMS
// standard error relative to the mean), with each pixel relative to its own
// value where that is brighter, so a few very bright pixels (a light's hot
// spot) do not hold up the whole image, and dark ones count against M.
static bool accum_error(st_world *w, const st_target *t, uint32_t n, st_err *err) {
    size_t px = (size_t)t->width * t->height;
    if (!w->acc_read && !(w->acc_read = malloc(px * 4 * sizeof(float))))
        return st_fail(err, ST_ERR_RUNTIME, "out of memory reading back %dx%d", t->width,
                       t->height);
    glGetTextureImage(t->color[0], 0, GL_RGBA, GL_FLOAT, (GLsizei)(px * 4 * sizeof(float)),
                      w->acc_read);
    double sum_m = 0, sum_e = 0;
    for (size_t k = 0; k < px; k++) {
        const float *a = w->acc_read + 4 * k;
        sum_m += ((double)a[0] + a[1] + a[2]) / 3.0 / n;
    }
    double M2 = (sum_m / px) * (sum_m / px);
    for (size_t k = 0; k < px; k++) {
        const float *a = w->acc_read + 4 * k;
        double m = ((double)a[0] + a[1] + a[2]) / 3.0 / n;
        double var_mean = fmax(0.0, (a[3] - n * m * m) / (n - 1)) / n;
        sum_e += var_mean / (m * m + M2);
    }
    w->acc_err = M2 > 0 ? sqrt(sum_e / px) : 0;
    if (!isfinite(w->acc_err)) w->acc_err = INFINITY;
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
    st_shader_set_int(w->accumulate, "st_acc_first", w->acc_n == 0);
    st_shader_set_float(w->accumulate, "st_acc_n", (float)(w->acc_n + 1));
    st_draw_fullscreen();
    w->acc_cur = next;
    w->acc_n++;
    c->current = c->accum[next].color[1];
    if (!st_gl_check("accumulate", err)) return false;
    w->acc_err = INFINITY;
    if (!modules_settled(w)) {
        w->acc_n = 0; // the next frame starts again (at the centre)
    } else {
        uint32_t cap = w->opts.filter_max_frames > 0 ? (uint32_t)w->opts.filter_max_frames
                                                     : ST_FILTER_MAX_FRAMES;
        double tol = w->opts.filter_tolerance != 0 ? w->opts.filter_tolerance : ST_FILTER_TOLERANCE;
        if (w->acc_n >= 4 || (w->acc_n >= cap && w->acc_n >= 2))
            if (!accum_error(w, &c->accum[next], w->acc_n, err)) return false;
        if (w->acc_n == 1 && cap == 1) w->acc_err = 0;
        w->acc_done = w->acc_n >= cap || (w->acc_n >= 4 && w->acc_err <= tol);
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

bool st_filter_begin(st_world *w) {
    unsigned outside = w->changes;
    for (int m = 0; m < w->num_mods; m++)
        if (w->mods[m]->params_dirty) outside |= ST_CHANGE_PARAMS;
    if (outside) w->acc_n = 0, w->acc_done = false, w->acc_err = INFINITY;
    if (w->acc_done) return false;
    // Only what depends on the camera redoes a jittered frame.
    float j[2];
    st_jitter_offset(w->acc_n, j);
    if (j[0] != w->jitter[0] || j[1] != w->jitter[1]) w->changes |= ST_CHANGE_CAMERA;
    memcpy(w->jitter, j, sizeof j);
    jitter_matrices(w);
    return true;
}
