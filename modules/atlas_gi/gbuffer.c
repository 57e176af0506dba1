// atlas_gi: the G-buffer pass. It rasterizes every triangle at its atlas
// position (plus one point per texel the rasterizer would miss) into the
// atlas' position and area, normal and validity, albedo and direct +
// emitted radiance (with shadow_map's visibility when it is loaded).
//
// A relight in mode=transfer redraws L0 alone: positions, normals and albedos
// do not depend on the light, and only the transfer's texels' L0 reaches the
// image (the reduce reads nothing else; the combined atlas, which reads every
// texel's, is shown by display=atlas only, and the gather reads every texel:
// both get the whole pass). The other texels (gutters, sealed texels) are
// discarded, which skips the lighting of whole blocks of them on llvmpipe;
// the same triangles in the same order give the same values bit for bit.
#include "agi.h"

static bool l0_only(const agi *g, const st_frame *f) {
    return ip(g, P_MODE) == 0 && ip(g, P_DISPLAY) != 3 && g->have_transfer && g->TG.leaf_tex &&
           !(f->changes & (ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY | ST_CHANGE_PROGRAMS));
}

bool agi_gbuffer_pass(agi *g, const st_frame *f, st_err *err) {
    bool shadow = st_world_has_module(g->w, "shadow_map"), part = l0_only(g, f);
    glBindFramebuffer(GL_FRAMEBUFFER, part ? g->fbo_l0 : g->fbo_gb);
    glViewport(0, 0, g->W, g->H);
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < 4 && !part; i++)
        glClearBufferfv(GL_COLOR, i, zero);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    // Program: PR_GBUFFER + shadow + 2 points + 4 L0 only (agi.h's order).
    int base = PR_GBUFFER + (shadow ? 1 : 0) + (part ? 4 : 0);
    // Points first: triangles overwrite wherever their rasterizer reaches.
    st_shader *pts = st_frame_use_program(f, base + 2, err);
    if (!pts) return false;
    st_shader_texture(pts, "ag_area_tex", GL_TEXTURE_2D, g->tex[T_AREA]);
    st_shader_texture(pts, "ag_leaf", GL_TEXTURE_2D, g->TG.leaf_tex);
    st_shader_set_vec2(pts, "ag_size", (float)g->W, (float)g->H);
    if (g->num_points) {
        glBindVertexArray(g->pts_vao);
        glDrawArrays(GL_POINTS, 0, g->num_points);
    }
    st_shader *tris = st_frame_use_program(f, base, err);
    if (!tris) return false;
    st_shader_texture(tris, "ag_area_tex", GL_TEXTURE_2D, g->tex[T_AREA]);
    st_shader_texture(tris, "ag_leaf", GL_TEXTURE_2D, g->TG.leaf_tex);
    st_model_type_draw(&g->type, g->models, g->num_models, tris);
    agi_prof_mark(g, g->prof_gb, 0);
    g->shadow = shadow;
    g->l0_partial = part;
    g->gb_dirty = false;
    g->have_cdf = false;
    g->restart = true;
    return st_gl_check("atlas_gi G-buffer", err);
}
