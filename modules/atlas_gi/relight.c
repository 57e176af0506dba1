// atlas_gi, mode=transfer: the precomputed transfer (transfer.h) built once
// per atlas from the G-buffer, and the relight: per bounce a reduction up the
// cluster tree, one pass over the links and a push down to the texels
// (transfer_gpu.h). Deterministic: one frame. profile=true times its steps
// (profile.c).
#include "agi.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

// One bounce: reduce, links, push (into fbo_gather[b & 1]; the last bounce
// also writes the accumulation).
static bool relight_bounce(agi *g, const st_frame *f, int b, double (*ms)[AG_PROF_STEPS],
                           st_err *err) {
    const transfer *T = &g->T;
    bool last = b == ip(g, P_BOUNCES) - 1;
    st_shader *reduce = st_world_program(g->w, g->p, PR_REDUCE, err);
    st_shader *sum = reduce ? st_world_program(g->w, g->p, PR_SUM, err) : NULL;
    st_shader *push = sum ? st_world_program(g->w, g->p, PR_PUSH, err) : NULL;
    if (!push) return false;
    tr_gpu_reduce(&g->TG, reduce, T, g->tex[T_L0], g->tex[b & 1 ? T_BOUNCE0 : T_BOUNCE1], b > 0,
                  g->tex[T_AREA]);
    agi_prof_mark(g, ms, 1);
    // The links program with the world's uniforms (the medium).
    int links = f->scene->medium.present ? PR_LINKS_MEDIUM : PR_LINKS;
    st_shader *sh = st_frame_use_program(f, links, err);
    if (!sh) return false;
    tr_gpu_links(&g->TG, sh, sum);
    agi_prof_mark(g, ms, 2);
    GLuint fbo = g->fbo_gather[b & 1];
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, last ? GL_COLOR_ATTACHMENT1 : GL_NONE};
    glNamedFramebufferDrawBuffers(fbo, 2, bufs);
    glDisablei(GL_BLEND, 0);
    glDisablei(GL_BLEND, 1);
    tr_gpu_push(&g->TG, push, g->tex[T_ALBEDO], g->tex[T_POS]);
    agi_prof_mark(g, ms, 3);
    return true;
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
        if (!relight_bounce(g, f, b, ms, err)) return false;
    for (int i = 0; i < TRG_COUNT; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, 0);
    g->frames = 1;
    g->restart = false;
    if (!agi_resolve(g, err)) return false;
    agi_prof_mark(g, ms, 4);
    agi_prof_keep(g, ms);
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
    agi_prof_info(g, out, n, size);
}
