// atlas_gi, mode=transfer: the precomputed transfer (transfer.h) built once
// per atlas from the G-buffer, and the relight: per bounce a reduction up the
// cluster tree, one pass over the links and a push down to the texels
// (transfer_gpu.h). Deterministic: one frame. profile=true times its steps.
#define _POSIX_C_SOURCE 200809L // clock_gettime (profile)
#include "agi.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char *const prof_names[AG_PROF_STEPS] = {"G-buffer", "reduce", "links", "push",
                                                      "resolve"};

void agi_release_transfer(agi *g) {
    tr_gpu_release(&g->TG);
    transfer_free(&g->T);
    g->have_transfer = false;
}

// The precomputed transfer, built on first use per atlas from the G-buffer's
// texel positions and normals (read back once) and uploaded for the relight
// passes.
static bool ensure_transfer(agi *g, st_err *err) {
    if (g->have_transfer) return true;
    size_t cells = (size_t)g->W * g->H;
    float *pos = malloc(cells * 4 * sizeof *pos), *nrm = malloc(cells * 4 * sizeof *nrm);
    uint32_t ntri = 0;
    float *tris = pos && nrm ? agi_scene_triangles(g, &ntri, err) : NULL;
    if (!tris) {
        free(pos);
        free(nrm);
        return pos && nrm ? false : st_fail(err, ST_ERR_RUNTIME, "out of memory");
    }
    glGetTextureImage(g->tex[T_POS], 0, GL_RGBA, GL_FLOAT, (GLsizei)(cells * 4 * sizeof *pos), pos);
    glGetTextureImage(g->tex[T_NORMAL], 0, GL_RGBA, GL_FLOAT, (GLsizei)(cells * 4 * sizeof *nrm),
                      nrm);
    tr_opts o = {
        .eps = g->p[P_TRANSFER_EPS],
        .recv = 0.25,
        .near_k = 2.0,
        .cone_deg = 20.0,
        .samples = 4,
        .kernel = 16,
        .spread = g->p[P_TRANSFER_EPS] / 50,
        .min_split = 4,
        .leaf_size = 0.05,
        .offset = 1e-4 * g->extent,
        .visibility = ip(g, P_VISIBILITY) != 0,
        .max_leaves = ip(g, P_TRANSFER_LEAVES),
    };
    bool ok = transfer_build(&g->T, g->W, g->H, pos, nrm, tris, ntri, &o, err);
    free(pos);
    free(nrm);
    free(tris);
    if (!ok) return false;
    if (!tr_gpu_upload(&g->TG, &g->T, err)) return false;
    g->have_transfer = true;
    return true;
}

void agi_prof_mark(agi *g, double (*acc)[AG_PROF_STEPS], int step) {
    if (!ip(g, P_PROFILE)) return;
    glFinish();
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    double t[2] = {st_now_ms(), ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6};
    for (int i = 0; i < 2; i++) {
        if (acc) acc[i][step] += t[i] - g->prof_t[i];
        g->prof_t[i] = t[i];
    }
}

typedef struct {
    agi *g;
    const st_frame *f;
} links_ctx;

static void links_setup(void *ctx, st_shader *sh) {
    const links_ctx *c = ctx;
    st_world_apply_uniforms(c->g->w, sh, c->f); // the medium
}

// One bounce: reduce, links, push (into fbo_gather[b & 1]; the last bounce
// also writes the accumulation).
static void relight_bounce(agi *g, const st_frame *f, int b, double (*ms)[AG_PROF_STEPS]) {
    const transfer *T = &g->T;
    bool last = b == ip(g, P_BOUNCES) - 1;
    tr_gpu_reduce(&g->TG, T, g->tex[T_L0], g->tex[b & 1 ? T_BOUNCE0 : T_BOUNCE1], b > 0,
                  g->tex[T_AREA]);
    agi_prof_mark(g, ms, 1);
    links_ctx lc = {g, f};
    tr_gpu_links(&g->TG, f->scene->medium.present, links_setup, &lc);
    agi_prof_mark(g, ms, 2);
    GLuint fbo = g->fbo_gather[b & 1];
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, last ? GL_COLOR_ATTACHMENT1 : GL_NONE};
    glNamedFramebufferDrawBuffers(fbo, 2, bufs);
    glDisablei(GL_BLEND, 0);
    glDisablei(GL_BLEND, 1);
    tr_gpu_push(&g->TG, g->tex[T_ALBEDO], g->tex[T_POS]);
    agi_prof_mark(g, ms, 3);
}

bool agi_transfer_pass(agi *g, const st_frame *f, st_err *err) {
    if (!ensure_transfer(g, err)) return false;
    const transfer *T = &g->T;
    // No clear of the accumulation: the last bounce's push writes every texel.
    if (!T->num_nodes) {
        const float zero[4] = {0, 0, 0, 0};
        glClearTexImage(g->tex[T_ACCUM], 0, GL_RGBA, GL_FLOAT, zero);
    }
    glViewport(0, 0, g->W, g->H);
    glDisable(GL_DEPTH_TEST);
    double ms[2][AG_PROF_STEPS] = {{g->prof_gb[0][0]}, {g->prof_gb[1][0]}};
    memset(g->prof_gb, 0, sizeof g->prof_gb);
    agi_prof_mark(g, NULL, 0);
    for (int b = 0; b < ip(g, P_BOUNCES) && T->num_nodes; b++)
        relight_bounce(g, f, b, ms);
    for (int i = 0; i < TRG_COUNT; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, 0);
    g->frames = 1;
    g->restart = false;
    agi_resolve(g);
    agi_prof_mark(g, ms, 4);
    if (ip(g, P_PROFILE)) {
        int k = g->prof_n % AG_PROF_MAX;
        for (int c = 0; c < 2; c++)
            for (int i = 0; i < AG_PROF_STEPS; i++)
                g->prof[c][i][k] = (float)ms[c][i];
        g->prof_n++;
    }
    g->rel_err = 0;
    g->converged = true;
    return st_gl_check("atlas_gi transfer", err);
}

void agi_relight_info(const agi *g, char *out, size_t size) {
    const transfer *T = &g->T;
    uint32_t texels = T->num_nodes ? T->nodes[0].end : 0;
    const double mib = 1048576.0;
    int n = snprintf(
        out, size,
        "transfer precompute %.2f s (CPU %.2f s) on %d threads, %u texels, %d nodes (<= %d "
        "texels per leaf, %u buried, %u sealed), %llu links, %llu rays, %.1f MiB; GPU %.1f MiB "
        "(nodes %.1f, "
        "links %.1f, gathered %.1f, perm %.1f, leaf map %.1f)",
        T->seconds, T->cpu_seconds, T->threads, texels, T->num_nodes, T->leaf_texels, T->buried,
        T->sealed, (unsigned long long)T->num_links, (unsigned long long)T->rays,
        transfer_bytes(T) / mib, g->TG.bytes / mib, g->TG.mem[TRG_MEM_NODES] / mib,
        g->TG.mem[TRG_MEM_LINKS] / mib, g->TG.mem[TRG_MEM_GATHERED] / mib,
        g->TG.mem[TRG_MEM_PERM] / mib, g->TG.mem[TRG_MEM_LEAF] / mib);
    int np = g->prof_n < AG_PROF_MAX ? g->prof_n : AG_PROF_MAX;
    for (int i = 0; i < AG_PROF_STEPS && np && n > 0 && (size_t)n < size; i++)
        n += snprintf(
            out + n, size - (size_t)n, "%s%s %.2f / %.2f",
            i ? ", " : "; relight steps (median ms wall / process CPU, profile): ", prof_names[i],
            st_median_f(g->prof[0][i], np), st_median_f(g->prof[1][i], np));
}
