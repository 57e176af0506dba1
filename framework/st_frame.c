// One frame: the regular pass, each live and needed module pass with its
// target bound, timing; reading the final image.
#include "st_world_state.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void make_frame(st_world *w, st_frame *f) {
    memset(f, 0, sizeof *f);
    f->world = w;
    f->scene = w->scene;
    f->index = w->frame;
    f->width = w->cam.width;
    f->height = w->cam.height;
    f->view = w->cam.view;
    f->proj = w->cam.proj;
    f->view_proj = w->cam.view_proj;
    f->inv_view_proj = w->cam.inv_view_proj;
    if (w->opts.filter == ST_FILTER_BOX) {
        f->proj = w->jit_proj;
        f->view_proj = w->jit_vp;
        f->inv_view_proj = w->jit_ivp;
    }
    f->cam_pos = w->cam.position;
    f->fov_y = w->cam.fov_y;
    f->near_z = w->cam.near_z;
    f->far_z = w->cam.far_z;
    f->gbuffer = w->cam.scene.color[1];
    f->albedo = w->cam.scene.color[2];
    f->depth = w->cam.scene.depth;
    f->hdr_in = w->cam.current;
    f->filter = w->opts.filter;
    if (w->opts.filter == ST_FILTER_BOX) memcpy(f->jitter, w->jitter, sizeof f->jitter);
}

static bool regular_pass(st_world *w, st_frame *f, st_err *err) {
    st_target_bind(&w->cam.scene);
    const float zero[4] = {0, 0, 0, 0}, nogeo[4] = {0, 0, 0, -1};
    const float *bg = w->scene->background; // where no geometry is drawn (black by default)
    glClearBufferfv(GL_COLOR, 0, (const float[]){bg[0], bg[1], bg[2], 0});
    glClearBufferfv(GL_COLOR, 1, nogeo);
    glClearBufferfv(GL_COLOR, 2, zero);
    glClearBufferfv(GL_DEPTH, 0, (const float[]){1.0f});
    st_filter_mask_prefill(w);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    st_shader_use(w->regular);
    st_world_apply_uniforms(w, w->regular, f);
    st_world_draw(w, w->regular);
    // With a medium the background is dimmed per pixel (far / cos), which a
    // clear colour cannot do: drawn at depth 1 where no geometry is.
    if (w->background && w->scene->medium.present) {
        glDepthFunc(GL_EQUAL);
        glDepthMask(GL_FALSE);
        glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glColorMaski(2, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        st_shader_use(w->background);
        st_world_apply_uniforms(w, w->background, f);
        st_shader_set_vec3(w->background, "st_background_radiance", bg);
        st_draw_fullscreen();
        glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glColorMaski(2, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthMask(GL_TRUE);
        glDepthFunc(GL_LESS);
    }
    glDisable(GL_DEPTH_TEST);
    w->cam.current = w->cam.scene.color[0];
    w->cam.post_out = 0;
    return st_gl_check("regular pass", err);
}

// A compute pass (ABI 1.4): one invocation per texel (and layer, unless
// ST_PASS_PLANE) of the first world-owned target the pass writes, bound as
// image unit 0; its writes are visible to the image loads and texture
// fetches of the passes after it.
static bool dispatch(st_world *w, st_slot *s, st_err *err) {
    int i = st_graph_target(w, s);
    if (i < 0)
        return st_fail(err, ST_ERR_RUNTIME, "compute pass '%s' writes no declared target",
                       s->info.name);
    if (!st_targets_ensure(&w->targets, i, w->cam.width, w->cam.height, err)) return false;
    const st_target *t = &w->targets.t[i].t;
    GLint prog = 0, size[3] = {1, 1, 1};
    glGetIntegerv(GL_CURRENT_PROGRAM, &prog);
    glGetProgramiv((GLuint)prog, GL_COMPUTE_WORK_GROUP_SIZE, size);
    int depth = (s->info.flags & ST_PASS_PLANE) || t->layers < 1 ? 1 : t->layers;
    bool layered = t->type == GL_TEXTURE_2D_ARRAY || t->type == GL_TEXTURE_CUBE_MAP_ARRAY;
    glBindImageTexture(0, t->color[0], 0, layered, 0, GL_WRITE_ONLY, t->color_format);
    glDispatchCompute((GLuint)((t->width + size[0] - 1) / size[0]),
                      (GLuint)((t->height + size[1] - 1) / size[1]),
                      (GLuint)((depth + size[2] - 1) / size[2]));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    return true;
}

static bool run_slot(st_world *w, st_slot *s, st_frame *f, st_err *err) {
    if (!s->mod) return regular_pass(w, f, err);
    st_module_inst *mi = s->mod;
    const st_plugin *p = mi->p;
    bool to_hdr = s->info.stage == ST_STAGE_POST && (s->writes.bits[0] & (1ull << RES_HDR));
    GLuint fbo = p->rendertarget ? p->rendertarget(mi->self, s->pass) : 0;
    f->hdr_in = w->cam.current;
    if (fbo) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    } else if (to_hdr) {
        st_target_bind(&w->cam.post[w->cam.post_out]);
    } else {
        int t = st_graph_target(w, s); // the world-owned target this pass writes, if any
        if (t >= 0) {
            if (!st_targets_ensure(&w->targets, t, w->cam.width, w->cam.height, err)) return false;
            st_target_bind(&w->targets.t[t].t);
        }
    }
    if (to_hdr) glViewport(0, 0, w->cam.width, w->cam.height);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    if (s->info.flags & ST_PASS_SCENE) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
    // A converging still's frozen pixels: a fullscreen pass onto the image
    // skips them (st_filter_mask.c).
    st_target *masked = !fbo && to_hdr && !(s->info.flags & ST_PASS_SCENE) && st_filter_masked(w)
                            ? &w->cam.post[w->cam.post_out]
                            : NULL;
    if (masked) st_filter_mask_post(w, masked, true);
    st_shader *sh = NULL;
    st_passes_frame(mi, s->pass, f);
    if (!st_passes_shader(w, mi, s->pass, f, &sh, err)) {
        st_err_prefix(err, "module '%s', pass '%s': ", p->name, s->info.name);
        return false;
    }
    f->shader = p->passes ? sh : NULL;
    if (sh) st_world_bind_pass(w, mi, sh, f);
    if (p->on_pass && !p->on_pass(mi->self, s->pass, f, err)) {
        st_err_prefix(err, "module '%s', pass '%s': ", p->name, s->info.name);
        return false;
    }
    // The world dispatches the compute programs it owns; a compute program
    // from the shader hook is dispatched by the plugin. on_pass may have
    // bound a second program (st_frame_use_program): the world draws or
    // dispatches with the pass's own one, bound again.
    bool compute = sh && sh->cs[0] && st_passes_owns(mi, sh);
    bool draws = compute || (sh && (s->info.flags & (ST_PASS_SCENE | ST_PASS_FULLSCREEN)));
    GLint current = 0;
    if (draws) glGetIntegerv(GL_CURRENT_PROGRAM, &current);
    if (draws && (GLuint)current != sh->program) st_world_bind_pass(w, mi, sh, f);
    if (compute) {
        if (!dispatch(w, s, err)) return false;
    } else if (sh && (s->info.flags & ST_PASS_SCENE)) {
        st_world_draw(w, sh);
    } else if (sh && (s->info.flags & ST_PASS_FULLSCREEN)) {
        st_draw_fullscreen();
    }
    if (p->after_pass) p->after_pass(mi->self, s->pass, f);
    if (masked) st_filter_mask_post(w, masked, false);
    glDisable(GL_DEPTH_TEST);
    if (to_hdr) {
        w->cam.current = w->cam.post[w->cam.post_out].color[0];
        w->cam.post_out ^= 1;
    }
    char what[160];
    snprintf(what, sizeof what, "module '%s', pass '%s'", p->name, s->info.name);
    return st_gl_check(what, err);
}

// Runs every live and needed pass in order, timing each.
static bool run_passes(st_world *w, st_frame *f, st_err *err) {
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        st_pass_stats *ps = &w->stats[s->stats];
        ps->ran_last_frame = false;
        ps->culled_last_frame = !s->live;
        if (!s->live) {
            ps->culled++;
            continue;
        }
        if (!s->needed) {
            ps->skipped++;
            continue;
        }
        f->changes = s->pending;
        double t0 = st_now_ms();
        if (s->query[0]) glQueryCounter(s->query[0], GL_TIMESTAMP);
        // One debug group per pass, named as in --stats, so GPU captures
        // (RenderDoc, apitrace) read like the stats table.
        char group[2 * ST_NAME_MAX + 2];
        snprintf(group, sizeof group, "%s/%s", ps->module, ps->pass);
        glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, (GLuint)i, -1, group);
        bool ok = run_slot(w, s, f, err);
        glPopDebugGroup();
        if (s->query[1]) glQueryCounter(s->query[1], GL_TIMESTAMP);
        if (!ok) return false;
        double t1 = st_now_ms();
        s->pending = 0;
        ps->runs++;
        ps->ran_last_frame = true;
        if (ps->num_samples < ST_STATS_MAX_SAMPLES) {
            ps->cpu_ms[ps->num_samples] = (float)(t1 - t0);
            ps->gpu_ms[ps->num_samples] = -1;
            ps->num_samples++;
        }
    }
    return true;
}

// Reads back this frame's GPU timestamps (--stats).
static void read_timings(st_world *w) {
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        st_pass_stats *ps = &w->stats[s->stats];
        if (!s->query[0] || !ps->ran_last_frame) continue;
        GLuint64 t0 = 0, t1 = 0;
        glGetQueryObjectui64v(s->query[0], GL_QUERY_RESULT, &t0);
        glGetQueryObjectui64v(s->query[1], GL_QUERY_RESULT, &t1);
        ps->gpu_ms[ps->num_samples - 1] = (float)((t1 > t0 ? t1 - t0 : 0) * 1e-6);
    }
}

bool st_world_frame(st_world *w, st_err *err) {
    if (w->opts.filter == ST_FILTER_BOX && !st_filter_begin(w)) {
        // Converged and nothing changed: the mean stays, no pass runs.
        for (int i = 0; i < w->num_stats; i++)
            w->stats[i].ran_last_frame = false;
        for (int i = 0; i < w->num_slots; i++)
            w->stats[w->slots[i].stats].skipped++;
        w->frame++;
        return true;
    }
    // Distribute this frame's changes to every pass.
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        s->pending |= w->changes;
        if (s->mod && s->mod->params_dirty) s->pending |= ST_CHANGE_PARAMS;
    }
    for (int m = 0; m < w->num_mods; m++)
        w->mods[m]->params_dirty = false;
    w->changes = 0;

    st_frame f;
    make_frame(w, &f);
    st_graph_cull(w, &f);
    if (w->opts.filter == ST_FILTER_BOX) st_filter_mask_gate(w);
    if (!run_passes(w, &f, err)) return false;
    if (w->opts.timing) read_timings(w);
    if (w->opts.filter == ST_FILTER_BOX && !st_filter_accumulate(w, err)) return false;
    w->frame++;
    return st_gl_check("frame", err);
}

bool st_world_read(st_world *w, st_image *out, st_err *err) {
    int W_ = w->cam.width, H = w->cam.height;
    st_target tmp = {0};
    // The latest image may be a post target or the scene target's colour 0.
    const st_target *src = &w->cam.scene;
    int index = 0;
    for (int i = 0; i < 2; i++) {
        if (w->cam.post[i].color[0] == w->cam.current) src = &w->cam.post[i];
        if (w->cam.accum[i].color[1] && w->cam.accum[i].color[1] == w->cam.current)
            src = &w->cam.accum[i], index = 1;
    }
    float *rgba = malloc((size_t)W_ * H * 4 * sizeof(float));
    if (!rgba) return st_fail(err, ST_ERR_RUNTIME, "out of memory reading %dx%d", W_, H);
    bool ok = st_target_read(src, index, rgba, err);
    (void)tmp;
    if (ok) ok = st_image_alloc(out, W_, H, 3, err);
    if (ok) {
        for (size_t k = 0; k < (size_t)W_ * H; k++)
            for (int c = 0; c < 3; c++)
                out->data[3 * k + c] = rgba[4 * k + c];
    }
    free(rgba);
    return ok;
}

void st_world_draw(st_world *w, st_shader *sh) {
    st_model_type_draw(&w->type, w->models, w->num_models, sh);
}
