// The built-in uniforms (thesis: Camera and Light are uniform providers):
// a name and a setter each, applied with the modules' own to every shader
// the world binds.
#include "st_world_state.h"
#include <cglm/cglm.h>

#define W(self) ((st_world *)(self))
static void u_view(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->view);
}
static void u_proj(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->proj);
}
static void u_vp(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->view_proj);
}
static void u_ivp(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->inv_view_proj);
}
static void u_cam(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform3fv(l, 1, f->cam_pos);
}
static void u_near(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, f->near_z);
}
static void u_far(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, f->far_z);
}
static void u_fov(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, glm_rad(f->fov_y));
}
static void u_res(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform2f(l, (float)f->width, (float)f->height);
}
static void u_frame(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, (int)(f->index & 0x7fffffff));
}
// The box filter's sample index: the frame's place in the running mean (0 on
// the point filter and on a restarted mean), so a module can stratify its own
// jitter over the frames the still averages (froxel's sample positions).
static void u_fsample(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, W(s)->opts.filter == ST_FILTER_BOX ? (int)(W(s)->acc_n & 0x7fffffff) : 0);
}
// The box filter's sub-pixel offset of this frame in GL window coordinates
// (pixels, x right, y up: st_jitter_offset's y points down), the pixel
// centre's place inside the pixel it stands for; z = 1 with the box filter,
// 0 (and no offset) with the point filter. A module that integrates a steep
// term over the pixel itself (toth's glow) needs the footprint.
static void u_pixel(void *s, st_shader *sh, GLint l, const st_frame *f) {
    bool box = W(s)->opts.filter == ST_FILTER_BOX;
    glUniform3f(l, box ? W(s)->jitter[0] : 0.0f, box ? -W(s)->jitter[1] : 0.0f, box ? 1.0f : 0.0f);
}
static void u_nl(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, W(s)->num_lights);
}
static void u_lp(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_pos[0][0]);
}
static void u_li(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_int[0][0]);
}
static void u_lt(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform1iv(l, W(s)->num_lights, W(s)->light_type);
}
static void u_ld(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_dir[0][0]);
}
static void u_lshape(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_shape[0][0]);
}
static void u_hasmed(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, f->scene->medium.present);
}
static void u_ss(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform3fv(l, 1, f->scene->medium.sigma_s);
}
static void u_sa(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform3fv(l, 1, f->scene->medium.sigma_a);
}
static void u_pk(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, (int)f->scene->medium.phase);
}
static void u_pg(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, f->scene->medium.g);
}

static const st_uniform builtin_uniforms[] = {
    {"st_view", u_view},
    {"st_proj", u_proj},
    {"st_view_proj", u_vp},
    {"st_inv_view_proj", u_ivp},
    {"st_cam_pos", u_cam},
    {"st_near", u_near},
    {"st_far", u_far},
    {"st_fov_y", u_fov},
    {"st_resolution", u_res},
    {"st_frame_index", u_frame},
    {"st_filter_sample", u_fsample},
    {"st_pixel_jitter", u_pixel},
    {"st_num_lights", u_nl},
    {"st_light_pos", u_lp},
    {"st_light_intensity", u_li},
    {"st_has_medium", u_hasmed},
    {"st_sigma_s", u_ss},
    {"st_sigma_a", u_sa},
    {"st_phase_kind", u_pk},
    {"st_phase_g", u_pg},
    {"st_light_type", u_lt},
    {"st_light_dir", u_ld},
    {"st_light_shape", u_lshape},
};

void st_world_apply_uniforms(st_world *w, st_shader *sh, const st_frame *f) {
    for (size_t i = 0; i < sizeof builtin_uniforms / sizeof builtin_uniforms[0]; i++) {
        GLint l = st_shader_loc(sh, builtin_uniforms[i].name);
        if (l >= 0) builtin_uniforms[i].set(w, sh, l, f);
    }
    st_medium_gpu_uniforms(&w->medium, sh);
    for (int m = 0; m < w->num_mods; m++) {
        for (int i = 0; i < w->mods[m]->num_uniforms; i++) {
            const st_uniform *u = &w->mods[m]->uniforms[i];
            GLint l = st_shader_loc(sh, u->name);
            if (l >= 0) u->set(w->mods[m]->self, sh, l, f);
        }
    }
    st_passes_apply_exports(w, sh);
}

void st_world_bind_pass(st_world *w, const st_module_inst *mi, st_shader *sh, const st_frame *f) {
    st_shader_use(sh);
    st_world_apply_uniforms(w, sh, f);
    st_shader_texture(sh, "st_hdr_in", GL_TEXTURE_2D, f->hdr_in);
    st_shader_texture(sh, "st_gbuffer", GL_TEXTURE_2D, f->gbuffer);
    st_shader_texture(sh, "st_albedo_tex", GL_TEXTURE_2D, f->albedo);
    st_passes_set_params(mi, sh);
}

st_shader *st_frame_use_program(const st_frame *f, int k, st_err *err) {
    st_module_inst *mi;
    st_shader *sh = st_passes_program_of(f->world, f->params, k, &mi, err);
    if (sh) st_world_bind_pass(f->world, mi, sh, f);
    return sh;
}
