// sousa: sun shafts (Sousa, CryEngine 2, GDC 2008; thesis 3.1 and 3.3.3,
// listings A.5-A.7). A linear camera-depth mask (far = emitting), then per
// light (point or sun) three radial-blur passes toward its screen position
// with step sizes TAPS^-1, TAPS^-2, TAPS^-3 (interleaved sampling), the last
// one adding the result to the scene image. Several lights add up (thesis 3.1).
//
// The mask is read from the G-buffer's camera distance, so the scene is not
// drawn a second time. Passes run only when needed: without a scattering
// medium, or when a light's fade (st_godray.h) is 0, the light's last
// pass is not needed and the world culls the rest of its chain and the mask;
// a static view reuses the mask and the first two blur passes.
#include "st_godray.h"
#include "st_world_api.h"
#include <math.h>
#include <stdio.h>

enum { P_TAPS, P_BRIGHTNESS, P_RESOLUTION, P_FADE_MARGIN, P_LIGHT_RADIUS, P_COUNT };

// Defaults: thesis figure 3.8 (TAPS 6, brightness 0.19); brightness range
// [0, 1] from 3.3.3; the thesis' depth map has the window's size.
static const st_param_def params[P_COUNT] = {
    {"taps", ST_PARAM_INT, 6, 2, 32, NULL,
     "taps per pass (TAPS); pass i steps TAPS^-i (texture coordinates) toward the light"},
    {"brightness", ST_PARAM_FLOAT, 0.19, 0, 1, NULL, "each pass multiplies its sum by brightness"},
    {"resolution", ST_PARAM_FLOAT, 1.0, 0.0625, 1, NULL,
     "mask and blur targets as a fraction of the screen, per axis (bilinear filtering)"},
    {"fade_margin", ST_PARAM_FLOAT, 0.5, 0.01, 10, NULL,
     "distance outside the screen, in screen heights, over which a light's shafts fade to zero"},
    {"light_radius", ST_PARAM_FLOAT, 0.1, 0.001, 100, NULL,
     "radius in metres a point light is taken to have when its radiance is compared with a sun's "
     "(the tint of scenes with both)"},
};

enum { MASK, BLUR1, BLUR2, BLUR3 }; // table rows

// Fullscreen post passes. The mask and, per light, the outputs of blur 1 and
// 2: `resolution` of the screen, taps outside reading 0 (no clamped edge
// streaks). The world sets the parameters as uniforms u_taps, u_brightness.
#define POST(name, reads, writes, local)                                                           \
    { name, ST_STAGE_POST, reads, writes, ST_PASS_FULLSCREEN | (local) }
#define TARGET .target = {GL_R32F, 1, false, true}, .scale_param = "resolution"
#define BLUR .frag = "sousa/blur.frag", .count = ST_PER_LIGHT // one chain per light
static const st_pass_decl passes[] = {
    // The mask samples the gbuffer at its own resolution: not pixel-local.
    {POST("mask", "gbuffer", "sousa.mask", 0), .frag = "sousa/mask.frag", TARGET},
    {POST("blur1", "sousa.mask", "sousa.blur1_%d", 0), BLUR, TARGET},
    {POST("blur2", "sousa.blur1_%d", "sousa.blur2_%d", 0), BLUR, TARGET},
    {POST("blur3", "hdr,sousa.blur2_%d", "hdr", ST_PASS_PIXEL_LOCAL), BLUR,
     .defines = "SOUSA_COMPOSE 1"},
};

static bool needed(void *self, int pass, const st_frame *f) {
    const double *p = f->params;
    // The G-buffer is rewritten every frame, but its content only changes
    // with the view or the scene, so ST_CHANGE_INPUTS alone does not count.
    const unsigned view =
        ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY | ST_CHANGE_CAMERA | ST_CHANGE_SIZE | ST_CHANGE_PARAMS;
    if (f->row == MASK) return f->changes & view;
    if (!(p[P_BRIGHTNESS] > 0) || !st_godray_light_active(f, f->instance, p[P_FADE_MARGIN]))
        return false;
    const float *bg = f->scene->background; // a black sky emits nothing
    if (f->scene->has_background && !(bg[0] > 0 || bg[1] > 0 || bg[2] > 0)) return false;
    if (f->row == BLUR3) return true; // composes onto this frame's image
    return f->changes & (view | ST_CHANGE_LIGHTS | ST_CHANGE_MEDIUM | ST_CHANGE_INPUTS);
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    const double *p = f->params;
    // The world has bound the program and the target each pass writes; the
    // last one writes the image. Blur i reads the mask or blur i-1's output.
    char name[ST_NAME_MAX] = "sousa.mask";
    if (f->row == BLUR2 || f->row == BLUR3)
        snprintf(name, sizeof name, "sousa.blur%d_%d", f->row - 1, f->instance);
    const st_target *src = st_world_target(f->world, name);
    if (!src) return st_fail(err, ST_ERR_RUNTIME, "no target %s", name);
    st_shader *sh = f->shader;
    // The mask and the blurs are one size; the last blur draws the screen.
    const int last = f->row == BLUR3, w = last ? f->width : src->width;
    st_shader_set_vec2(sh, "u_out_size", (float)w, (float)(last ? f->height : src->height));
    if (f->row == MASK) return st_gl_check("sousa mask", err);
    float tint[3];
    st_godray_light l =
        st_godray_light_state(f, f->instance, p[P_FADE_MARGIN], p[P_LIGHT_RADIUS], tint);
    // The mask's far value 1 is the sky; a scene background gives it its
    // radiance. (Only the last pass's program has u_color and u_fade.)
    for (int c = 0; c < 3 && f->scene->has_background; c++)
        tint[c] *= f->scene->background[c];
    st_shader_set_vec3(sh, "u_color", tint);
    st_shader_set_float(sh, "u_fade", l.fade);
    st_shader_texture(sh, "u_src", GL_TEXTURE_2D, src->color[0]);
    st_shader_set_vec2(sh, "u_light_uv", l.uv[0], l.uv[1]);
    // TAPS^-1, ^-2, ^-3 (figure 3.15)
    st_shader_set_float(sh, "u_step", (float)pow(p[P_TAPS], -f->row));
    return st_gl_check("sousa blur", err);
}

ST_PLUGIN(.name = "sousa",
          .description = "sun shafts (Sousa, CryEngine 2): linear depth mask blurred toward each "
                         "light in 3 passes with steps TAPS^-1, TAPS^-2, TAPS^-3; no occlusion of "
                         "the light: in a closed room with the light behind a wall every surface "
                         "is blurred toward it, a grey veil (modules/sousa/README.md)",
          ST_PARAMS(params), ST_PASSES(passes), .param_uniforms = "u_", .needed = needed,
          .on_pass = on_pass, .light_types = ST_GODRAY_LIGHT_TYPES)
