// atlas_gi: the G-buffer pass. It rasterizes every triangle at its atlas
// position (plus one point per texel the rasterizer would miss) into the
// atlas' position and area, normal and validity, albedo and direct +
// emitted radiance (with shadow_map's visibility when it is loaded).
#include "agi.h"

bool agi_gbuffer_pass(agi *g, const st_frame *f, st_err *err) {
    bool shadow = st_world_has_module(g->w, "shadow_map");
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_gb);
    glViewport(0, 0, g->W, g->H);
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < 4; i++)
        glClearBufferfv(GL_COLOR, i, zero);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    // Points first: triangles overwrite wherever their rasterizer reaches.
    st_shader *pts =
        st_frame_use_program(f, shadow ? PR_GBUFFER_POINTS_SHADOW : PR_GBUFFER_POINTS, err);
    if (!pts) return false;
    st_shader_texture(pts, "ag_area_tex", GL_TEXTURE_2D, g->tex[T_AREA]);
    st_shader_set_vec2(pts, "ag_size", (float)g->W, (float)g->H);
    if (g->num_points) {
        glBindVertexArray(g->pts_vao);
        glDrawArrays(GL_POINTS, 0, g->num_points);
    }
    st_shader *tris = st_frame_use_program(f, shadow ? PR_GBUFFER_SHADOW : PR_GBUFFER, err);
    if (!tris) return false;
    st_shader_texture(tris, "ag_area_tex", GL_TEXTURE_2D, g->tex[T_AREA]);
    st_model_type_draw(&g->type, g->models, g->num_models, tris);
    agi_prof_mark(g, g->prof_gb, 0);
    g->shadow = shadow;
    g->gb_dirty = false;
    g->have_cdf = false;
    g->restart = true;
    return st_gl_check("atlas_gi G-buffer", err);
}
