// atlas_gi, mode=gather: the thesis' per-frame gather. One bounce per texel
// from N Hammersley samples over the atlas (uniform, or power sampling by
// inverting a CDF of each texel's flux), repeated for more bounces,
// accumulated over frames under a Cranley-Patterson rotation until the mean
// converges; the resolve (atlas_gpu.c) dilates the result into the gutters.
#include "agi.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// The BVH for visibility, built on first use over every scene triangle once.
static bool ensure_bvh(agi *g, st_err *err) {
    if (g->have_bvh) return true;
    uint32_t n = 0;
    float *c = agi_scene_triangles(g, &n, err);
    if (!c) return false;
    bool ok = st_bvh_build(&g->B, c, n, err);
    free(c);
    if (!ok || !st_bvh_upload(&g->B_gpu, &g->B, err)) return false;
    if (!st_world_track(g->w, agi_buffer_names[7], GL_BUFFER, g->B_gpu.nodes, err) ||
        !st_world_track(g->w, agi_buffer_names[8], GL_BUFFER, g->B_gpu.tris, err))
        return false;
    g->have_bvh = true;
    return true;
}

// The sample texture (thesis 4.5): X_i = (i/N, radical inverse base 2 of i).
static void ensure_hammersley(agi *g) {
    int n = ip(g, P_SAMPLES);
    if (g->ham_n == n && g->ham_tex) return;
    float *v = realloc(g->ham, (size_t)n * 2 * sizeof *v);
    if (!v) return;
    g->ham = v;
    const st_target_desc d = {GL_RG32F, .type = GL_TEXTURE_1D, .width = n, .filter = GL_NEAREST};
    st_err ignore = {0};
    const st_target *t = st_world_alloc_target(g->w, "atlas_gi.hammersley", &d, &ignore);
    if (!t) return;
    g->ham_tex = t->color[0];
    st_hammersley_upload(g->ham_tex, n, v);
    g->ham_n = n;
}

// Power sampling: p_j = 3/4 a_j Y(L0_j) / sum + 1/4 a_j / sum a (the area part
// keeps every surface texel reachable, which later bounces need), from the
// G-buffer's L0 read back once per G-buffer.
static bool build_cdf(agi *g, st_err *err) {
    size_t n = (size_t)g->W * g->H;
    float *l0 = malloc(n * 4 * sizeof *l0), *pmf = realloc(g->pmf, n * sizeof *pmf);
    if (pmf) g->pmf = pmf;
    double *cdf = pmf ? realloc(g->cdf, n * sizeof *cdf) : NULL;
    if (cdf) g->cdf = cdf;
    double *rows = cdf ? realloc(g->cdf_row, ((size_t)g->H + 1) * sizeof *rows) : NULL;
    if (rows) g->cdf_row = rows;
    if (!l0 || !rows) {
        free(l0);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for the sampling distribution");
    }
    glGetTextureImage(g->tex[T_L0], 0, GL_RGBA, GL_FLOAT, (GLsizei)(n * 4 * sizeof *l0), l0);
    double sf = 0, sa = 0;
    for (size_t j = 0; j < n; j++) {
        double a = g->A.area[j],
               y = 0.2126 * l0[4 * j] + 0.7152 * l0[4 * j + 1] + 0.0722 * l0[4 * j + 2];
        sf += a * fmax(y, 0);
        sa += a;
    }
    rows[0] = 0;
    for (int y = 0; y < g->H; y++) {
        double acc = 0;
        for (int x = 0; x < g->W; x++) {
            size_t j = (size_t)y * g->W + x;
            double a = g->A.area[j],
                   lum = 0.2126 * l0[4 * j] + 0.7152 * l0[4 * j + 1] + 0.0722 * l0[4 * j + 2];
            double w =
                sa > 0 ? (sf > 0 ? 0.75 * a * fmax(lum, 0) / sf + 0.25 * a / sa : a / sa) : 0;
            pmf[j] = (float)w;
            acc += pmf[j];
            cdf[j] = acc;
        }
        rows[y + 1] = rows[y] + acc;
    }
    free(l0);
    g->have_cdf = rows[g->H] > 0;
    return st_gl_check("atlas_gi sampling distribution", err);
}

// The first index in v[0, n) whose value exceeds t (v non-decreasing).
static int upper(const double *v, int n, double t) {
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (v[mid] > t)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

// N picks by inverting the CDF at the rotated Hammersley points: texel x, y
// and 1/(N p); uploaded for the gather.
static bool upload_picks(agi *g, const float *rot, st_err *err) {
    int n = g->ham_n;
    if (g->pick_cap < n) {
        float *p = realloc(g->picks, (size_t)n * 4 * sizeof *p);
        if (!p) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
        g->picks = p;
        const st_target_desc d = {GL_RGBA32F, .type = GL_TEXTURE_1D, .width = n,
                                  .filter = GL_NEAREST};
        const st_target *t = st_world_alloc_target(g->w, "atlas_gi.picks", &d, err);
        if (!t) return false;
        g->pick_tex = t->color[0];
        g->pick_cap = n;
    }
    double total = g->cdf_row[g->H];
    for (int i = 0; i < n; i++) {
        double u = fmod(g->ham[2 * i] + rot[0], 1.0), v = fmod(g->ham[2 * i + 1] + rot[1], 1.0);
        int y = upper(g->cdf_row + 1, g->H, v * total);
        const double *c = g->cdf + (size_t)y * g->W;
        int x = upper(c, g->W, u * c[g->W - 1]); // the row's own sum: no rounding past its end
        double p = g->pmf[(size_t)y * g->W + x] / total;
        float *o = g->picks + 4 * (size_t)i;
        o[0] = (float)x, o[1] = (float)y, o[2] = p > 0 ? (float)(1.0 / (n * p)) : 0.0f, o[3] = 0;
    }
    glTextureSubImage1D(g->pick_tex, 0, 0, n, GL_RGBA, GL_FLOAT, g->picks);
    return st_gl_check("atlas_gi picks", err);
}

// The R2 sequence: a well-spread rotation per (frame, bounce), 0 at first.
static void rotation(int index, float *r) {
    r[0] = (float)fmod(index * 0.7548776662466927, 1.0);
    r[1] = (float)fmod(index * 0.5698402909980532, 1.0);
}

void agi_update_converged(agi *g) {
    if (ip(g, P_MODE) == 0)
        g->converged = g->frames >= 1; // transfer: deterministic
    else if (!ip(g, P_PROGRESSIVE))
        g->converged = g->frames >= 1;
    else if (g->frames >= ip(g, P_MAX_FRAMES))
        g->converged = true;
    else
        g->converged = g->frames >= 4 && g->rel_err <= g->p[P_TOLERANCE];
}

// One bounce b of the gather into fbo_gather[b & 1]; the last one adds its
// estimate to the running sums.
static bool gather_bounce(agi *g, const st_frame *f, int b, bool power, st_err *err) {
    bool last = b == ip(g, P_BOUNCES) - 1;
    GLuint fbo = g->fbo_gather[b & 1];
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, last ? GL_COLOR_ATTACHMENT1 : GL_NONE};
    glNamedFramebufferDrawBuffers(fbo, 2, bufs);
    glDisablei(GL_BLEND, 0);
    if (last) {
        glEnablei(GL_BLEND, 1);
        glBlendFunci(1, GL_ONE, GL_ONE);
        glBlendEquationi(1, GL_FUNC_ADD);
    }
    float rot[2];
    rotation(ip(g, P_PROGRESSIVE) ? g->frames * 8 + b : b, rot);
    if (power && !upload_picks(g, rot, err)) return false;
    // Bound with the world's uniforms: the medium's extinction per segment.
    st_shader *sh = st_frame_use_program(f, ip(g, P_VISIBILITY) ? PR_GATHER_VIS : PR_GATHER, err);
    if (!sh) return false;
    st_shader_texture(sh, "ag_pos", GL_TEXTURE_2D, g->tex[T_POS]);
    st_shader_texture(sh, "ag_normal", GL_TEXTURE_2D, g->tex[T_NORMAL]);
    st_shader_texture(sh, "ag_albedo", GL_TEXTURE_2D, g->tex[T_ALBEDO]);
    st_shader_texture(sh, "ag_l0", GL_TEXTURE_2D, g->tex[T_L0]);
    st_shader_texture(sh, "ag_prev", GL_TEXTURE_2D, g->tex[b & 1 ? T_BOUNCE0 : T_BOUNCE1]);
    st_shader_texture(sh, "ag_hammersley", GL_TEXTURE_1D, g->ham_tex);
    st_shader_texture(sh, "ag_picks", GL_TEXTURE_1D, power ? g->pick_tex : g->ham_tex);
    st_shader_set_int(sh, "ag_power", power);
    st_shader_set_int(sh, "ag_use_prev", b > 0);
    st_shader_set_int(sh, "ag_samples", g->ham_n);
    st_shader_set_int(sh, "ag_estimator", ip(g, P_ESTIMATOR));
    st_shader_set_vec2(sh, "ag_rotation", rot[0], rot[1]);
    st_shader_set_float(sh, "ag_offset", (float)(1e-4 * g->extent));
    st_draw_fullscreen();
    glDisablei(GL_BLEND, 1);
    return true;
}

// Relative standard error of the mean over the valid texels, from the 1x1
// mip level of the statistics (one small read back per frame).
static void measure_error(agi *g) {
    glGenerateTextureMipmap(g->tex[T_STATS]);
    float s[4] = {0, 0, 0, 0};
    glGetTextureImage(g->tex[T_STATS], g->stats_top, GL_RGBA, GL_FLOAT, sizeof s, s);
    g->rel_err = s[0] > 0 ? sqrt(fmax(s[1], 0) * fmax(s[2], 0)) / s[0] : 0;
    if (!isfinite(g->rel_err)) g->rel_err = INFINITY;
}

bool agi_gather_pass(agi *g, const st_frame *f, st_err *err) {
    ensure_hammersley(g);
    bool vis = ip(g, P_VISIBILITY) != 0;
    if (vis && !ensure_bvh(g, err)) return false;
    if (g->restart || (f->changes & (ST_CHANGE_FIRST | ST_CHANGE_INPUTS))) {
        g->frames = 0;
        g->rel_err = INFINITY;
        const float zero[4] = {0, 0, 0, 0};
        glClearTexImage(g->tex[T_ACCUM], 0, GL_RGBA, GL_FLOAT, zero);
        g->restart = false;
    }
    glViewport(0, 0, g->W, g->H);
    glDisable(GL_DEPTH_TEST);
    // The thesis estimator is defined for uniform picks only.
    bool power = ip(g, P_SAMPLING) == 1 && ip(g, P_ESTIMATOR) == 0;
    if (power && !g->have_cdf && !build_cdf(g, err)) return false;
    power = power && g->have_cdf;
    if (vis) st_bvh_bind(&g->B_gpu);
    for (int b = 0; b < ip(g, P_BOUNCES); b++)
        if (!gather_bounce(g, f, b, power, err)) return false;
    g->frames++;
    if (!agi_resolve(g, err)) return false;
    if (ip(g, P_PROGRESSIVE) && g->frames >= 4 && g->frames < ip(g, P_MAX_FRAMES)) measure_error(g);
    agi_update_converged(g);
    return st_gl_check("atlas_gi gather", err);
}

void agi_gather_free(agi *g) {
    free(g->ham);
    free(g->picks);
    free(g->pmf);
    free(g->cdf);
    free(g->cdf_row);
}
