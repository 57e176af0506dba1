// sousa: sun shafts (Sousa, CryEngine 2, GDC 2008; thesis 3.1 and 3.3.3,
// listings A.5-A.7). A linear camera-depth mask (far = emitting), then per
// light (point or sun) three radial-blur passes toward its screen position
// with step sizes TAPS^-1, TAPS^-2, TAPS^-3 (interleaved sampling), the last
// one adding the result to the scene image. Several lights add up (thesis 3.1).
//
// The mask is read from the G-buffer's camera distance, so the scene is not
// drawn a second time. Passes run only when needed: without a scattering
// medium, or when a light's fade (godray_screen.h) is 0, the light's last
// pass is not needed and the world culls the rest of its chain and the mask;
// a static view reuses the mask and the first two blur passes.
#include "godray_screen.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

enum { BLUR1, BLUR2, BLUR3, NUM_BLUR };

typedef struct sousa {
    st_world *w;
    const double *p;
    int num_lights;
    st_shader *mask_sh, *blur_sh, *compose_sh;
    st_pass_info info[1 + NUM_BLUR * ST_MAX_LIGHTS];
    char names[ST_MAX_LIGHTS][2][32], reads3[ST_MAX_LIGHTS][40];
} sousa;

static void destroy(void *self) {
    sousa *s = self;
    st_shader_destroy(s->mask_sh);
    st_shader_destroy(s->blur_sh);
    st_shader_destroy(s->compose_sh);
    free(s);
}

// The mask and the outputs of blur 1 and 2 per light, owned by the world:
// `resolution` of the screen, taps outside reading 0 (no clamped edge streaks).
static bool declare_targets(sousa *s, st_err *err) {
    const st_target_desc d = {GL_R32F, s->p[P_RESOLUTION], false, true};
    bool ok = st_world_declare_target(s->w, "sousa.mask", &d, err);
    for (int k = 0; ok && k < s->num_lights; k++)
        ok = st_world_declare_target(s->w, s->names[k][0], &d, err) &&
             st_world_declare_target(s->w, s->names[k][1], &d, err);
    return ok;
}

static void param_changed(void *self, int index) {
    st_err ignore = {0}; // only fails for a bad name, which create already caught
    if (index == P_RESOLUTION) declare_targets(self, &ignore);
}

static void *create(st_world *w, const double *p, st_err *err) {
    sousa *s = st_calloc(sizeof *s, err);
    if (!s) return NULL;
    s->w = w;
    s->p = p;
    s->num_lights = st_world_scene(w)->num_lights;
    if (s->num_lights > ST_MAX_LIGHTS) s->num_lights = ST_MAX_LIGHTS;
    s->mask_sh = st_shader_load("common/fullscreen.vert", "sousa/mask.frag", NULL, err);
    if (s->mask_sh)
        s->blur_sh = st_shader_load("common/fullscreen.vert", "sousa/blur.frag", NULL, err);
    if (s->blur_sh)
        s->compose_sh =
            st_shader_load("common/fullscreen.vert", "sousa/blur.frag", "SOUSA_COMPOSE 1", err);
    if (!s->compose_sh) {
        destroy(s);
        return NULL;
    }
    s->info[0] = (st_pass_info){"mask", ST_STAGE_POST, "gbuffer", "sousa.mask", ST_PASS_FULLSCREEN};
    for (int k = 0; k < s->num_lights; k++) {
        snprintf(s->names[k][0], sizeof s->names[k][0], "sousa.blur1_%d", k);
        snprintf(s->names[k][1], sizeof s->names[k][1], "sousa.blur2_%d", k);
        snprintf(s->reads3[k], sizeof s->reads3[k], "hdr,%s", s->names[k][1]);
        st_pass_info *in = &s->info[1 + NUM_BLUR * k];
        in[BLUR1] = (st_pass_info){"blur1", ST_STAGE_POST, "sousa.mask", s->names[k][0],
                                   ST_PASS_FULLSCREEN};
        in[BLUR2] = (st_pass_info){"blur2", ST_STAGE_POST, s->names[k][0], s->names[k][1],
                                   ST_PASS_FULLSCREEN};
        in[BLUR3] = (st_pass_info){"blur3", ST_STAGE_POST, s->reads3[k], "hdr", ST_PASS_FULLSCREEN};
    }
    if (!declare_targets(s, err)) {
        destroy(s);
        return NULL;
    }
    return s;
}

// Pass 0: the mask; then blur 1, 2, 3 of light 0, of light 1, ...
static int num_passes(void *self) {
    sousa *s = self;
    return s->num_lights ? 1 + NUM_BLUR * s->num_lights : 0;
}
static const st_pass_info *pass_info(void *self, int pass) {
    return &((sousa *)self)->info[pass];
}

static bool needed(void *self, int pass, const st_frame *f) {
    sousa *s = self;
    // The G-buffer is rewritten every frame, but its content only changes
    // with the view or the scene, so ST_CHANGE_INPUTS alone does not count.
    const unsigned view =
        ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY | ST_CHANGE_CAMERA | ST_CHANGE_SIZE | ST_CHANGE_PARAMS;
    if (pass == 0) return f->changes & view;
    int k = (pass - 1) / NUM_BLUR, b = (pass - 1) % NUM_BLUR;
    if (!(s->p[P_BRIGHTNESS] > 0) || !godray_light_active(f, k, s->p[P_FADE_MARGIN])) return false;
    const float *bg = f->scene->background; // a black sky emits nothing
    if (f->scene->has_background && !(bg[0] > 0 || bg[1] > 0 || bg[2] > 0)) return false;
    if (b == BLUR3) return true; // composes onto this frame's image
    return f->changes & (view | ST_CHANGE_LIGHTS | ST_CHANGE_MEDIUM | ST_CHANGE_INPUTS);
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    sousa *s = self;
    // The world has bound the target each pass writes; the last one writes the image.
    const st_target *mask = st_world_target(s->w, "sousa.mask");
    if (!mask) return st_fail(err, ST_ERR_RUNTIME, "no target sousa.mask");
    if (pass == 0) {
        st_shader_set_vec2(s->mask_sh, "u_out_size", (float)mask->width, (float)mask->height);
        return st_gl_check("sousa mask", err);
    }
    int k = (pass - 1) / NUM_BLUR, b = (pass - 1) % NUM_BLUR;
    float tint[3];
    godray_light l = godray_light_state(f, k, s->p[P_FADE_MARGIN], s->p[P_LIGHT_RADIUS], tint);
    st_shader *sh = b == BLUR3 ? s->compose_sh : s->blur_sh; // bound by the world
    const st_target *src = b == BLUR1 ? mask : st_world_target(s->w, s->names[k][b - 1]);
    if (!src) return st_fail(err, ST_ERR_RUNTIME, "no target %s", s->names[k][b - 1]);
    if (b != BLUR3) {
        st_shader_set_vec2(sh, "u_out_size", (float)src->width, (float)src->height); // all one size
    } else {
        st_shader_set_vec2(sh, "u_out_size", (float)f->width, (float)f->height);
        // The mask's far value 1 is the sky; a scene background gives it its radiance.
        if (f->scene->has_background)
            for (int c = 0; c < 3; c++)
                tint[c] *= f->scene->background[c];
        st_shader_set_vec3(sh, "u_color", tint);
        st_shader_set_float(sh, "u_fade", l.fade);
    }
    int taps = (int)s->p[P_TAPS];
    st_shader_texture(sh, "u_src", GL_TEXTURE_2D, src->color[0]);
    st_shader_set_vec2(sh, "u_light_uv", l.uv[0], l.uv[1]);
    st_shader_set_int(sh, "u_taps", taps);
    st_shader_set_float(sh, "u_step",
                        (float)pow(taps, -(b + 1))); // TAPS^-1, ^-2, ^-3 (figure 3.15)
    st_shader_set_float(sh, "u_brightness", (float)s->p[P_BRIGHTNESS]);
    return st_gl_check("sousa blur", err);
}

static st_shader *shader(void *self, int pass) {
    sousa *s = self;
    if (pass == 0) return s->mask_sh;
    return (pass - 1) % NUM_BLUR == BLUR3 ? s->compose_sh : s->blur_sh;
}

static bool reload(void *self, st_err *err) {
    sousa *s = self;
    return st_shader_reload(s->mask_sh, err) && st_shader_reload(s->blur_sh, err) &&
           st_shader_reload(s->compose_sh, err);
}

ST_PLUGIN(.name = "sousa",
          .description = "sun shafts (Sousa, CryEngine 2): linear depth mask blurred toward each "
                         "light in 3 passes with steps TAPS^-1, TAPS^-2, TAPS^-3",
          ST_PARAMS(params), .create = create, .destroy = destroy, .num_passes = num_passes,
          .pass_info = pass_info, .needed = needed, .on_pass = on_pass, .shader = shader,
          .param_changed = param_changed, .reload = reload, .light_types = GODRAY_LIGHT_TYPES)
