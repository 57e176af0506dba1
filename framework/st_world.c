// The World: owns the scene's GPU data, the camera, the loaded modules and
// the frame graph. Each frame: pre-passes, the regular pass, then the
// PostProcessor chain; passes nobody consumes are culled, passes whose
// inputs did not change are skipped (their cached output stays valid).
#define _POSIX_C_SOURCE 200809L
#include "st_physics.h"
#include "st_world_modules.h"
#include "st_world_regular.h"
#include "st_world_state.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void light_defines(st_world *w) {
    unsigned types = 0;
    for (int i = 0; i < w->scene->num_lights; i++)
        types |= 1u << w->scene->lights[i].type;
    snprintf(w->light_defines, sizeof w->light_defines, "ST_MAX_LIGHTS %d\nST_LIGHT_TYPES %u\n",
             ST_MAX_LIGHTS, types);
    st_medium_gpu_defines(w->scene, w->light_defines, sizeof w->light_defines);
}

static bool create_targets(st_world *w, st_err *err) {
    st_camera *c = &w->cam;
    st_target_destroy(&c->scene);
    st_target_destroy(&c->post[0]);
    st_target_destroy(&c->post[1]);
    st_target_destroy(&c->accum[0]);
    st_target_destroy(&c->accum[1]);
    w->acc_n = 0, w->acc_done = false, w->acc_err = INFINITY;
    free(w->acc_read);
    w->acc_read = NULL;
    for (int i = 0; w->opts.filter == ST_FILTER_BOX && i < 2; i++) {
        if (!st_target_create(&c->accum[i], c->width, c->height, 3, GL_RGBA32F, false, err))
            return false;
        char name[32];
        snprintf(name, sizeof name, "camera.accum%d", i);
        glObjectLabel(GL_FRAMEBUFFER, c->accum[i].fbo, -1, name);
    }
    if (w->opts.filter == ST_FILTER_BOX && !st_filter_mask_init(w, err)) return false;
    if (!st_target_create(&c->scene, c->width, c->height, 3, GL_RGBA32F, true, err) ||
        !st_target_create(&c->post[0], c->width, c->height, 1, GL_RGBA32F, false, err) ||
        !st_target_create(&c->post[1], c->width, c->height, 1, GL_RGBA32F, false, err))
        return false;
    // The resource names of the pass list, for debuggers.
    glObjectLabel(GL_FRAMEBUFFER, c->scene.fbo, -1, "camera.scene");
    glObjectLabel(GL_TEXTURE, c->scene.color[0], -1, "hdr");
    glObjectLabel(GL_TEXTURE, c->scene.color[1], -1, "gbuffer");
    glObjectLabel(GL_TEXTURE, c->scene.color[2], -1, "albedo");
    glObjectLabel(GL_TEXTURE, c->scene.depth, -1, "depth");
    for (int i = 0; i < 2; i++) {
        char name[32];
        snprintf(name, sizeof name, "camera.post%d", i);
        glObjectLabel(GL_FRAMEBUFFER, c->post[i].fbo, -1, name);
        snprintf(name, sizeof name, "hdr (post %d)", i);
        glObjectLabel(GL_TEXTURE, c->post[i].color[0], -1, name);
    }
    return st_gl_check("camera targets", err);
}

// The lights as the built-in uniforms give them (common/uniforms.glsl).
static void init_lights(st_world *w, const st_scene *scene) {
    w->num_lights = scene->num_lights;
    for (int i = 0; i < scene->num_lights; i++) {
        memcpy(w->light_pos[i], scene->lights[i].position, sizeof w->light_pos[i]);
        memcpy(w->light_int[i], scene->lights[i].intensity, sizeof w->light_int[i]);
        const st_light_desc *l = &scene->lights[i];
        w->light_type[i] = (int)l->type;
        memcpy(w->light_dir[i], l->direction, sizeof w->light_dir[i]);
        if (l->type == ST_LIGHT_SPOT) { // st_spot_falloff as scale and offset in cos
            double co = cos(l->outer_angle), scale = 1.0 / fmax(0.001, cos(l->inner_angle) - co);
            w->light_shape[i][0] = (float)scale, w->light_shape[i][1] = (float)(-co * scale);
        }
        if (l->type == ST_LIGHT_DIRECTIONAL) // no geometry: -inf, kept finite for GL
            w->light_shape[i][2] = (float)fmax(st_directional_entry(scene, l->direction), -1e30);
    }
}

// The camera of the scene at the size the options ask for.
static void init_camera(st_world *w, const st_scene *scene) {
    st_camera *c = &w->cam;
    memcpy(c->position, scene->camera.position, sizeof c->position);
    memcpy(c->target, scene->camera.target, sizeof c->target);
    memcpy(c->up, scene->camera.up, sizeof c->up);
    c->fov_y = scene->camera.fov_y;
    c->near_z = scene->camera.near_z;
    c->far_z = scene->camera.far_z;
    c->width = w->opts.width > 0 ? w->opts.width : scene->width;
    c->height = w->opts.height > 0 ? w->opts.height : scene->height;
    st_camera_update(c);
}

st_world *st_world_create(const st_scene *scene, const st_world_opts *opts, st_err *err) {
    st_world *w = calloc(1, sizeof *w);
    if (!w) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    w->scene = scene;
    light_defines(w);
    if (opts) w->opts = *opts;
    if (scene->num_lights > ST_MAX_LIGHTS) {
        st_fail(err, ST_ERR_INPUT, "%s: lights: %d lights, at most %d are supported", scene->path,
                scene->num_lights, ST_MAX_LIGHTS);
        free(w);
        return NULL;
    }
    if (!st_medium_gpu_create(&w->medium, scene, err)) {
        free(w);
        return NULL;
    }
    init_lights(w, scene);
    init_camera(w, scene);
    w->changes = ST_CHANGE_ALL;

    w->num_models = scene->num_meshes;
    w->models = calloc(w->num_models ? (size_t)w->num_models : 1, sizeof *w->models);
    bool ok = w->models && st_model_type_build(&w->type, "lit", scene->meshes, scene->num_meshes,
                                               NULL, w->models, err);
    if (!w->models) st_fail(err, ST_ERR_RUNTIME, "out of memory");
    if (ok) { // named as in st_world_memory
        glObjectLabel(GL_BUFFER, w->type.vbo.id, -1, "world.vertices");
        glObjectLabel(GL_BUFFER, w->type.ibo.id, -1, "world.indices");
    }
    ok = ok && create_targets(w, err);
    for (int i = 0; ok && i < scene->num_modules; i++)
        ok = st_world_load(w, scene->modules[i].name, err);
    ok = ok && st_world_resolve(w, err);
    for (int m = 0; ok && m < w->num_mods; m++)
        ok = st_world_instantiate(w, m, err);
    ok = ok && st_world_build_regular(w, err) && st_graph_build(w, err);
    if (ok && w->opts.filter == ST_FILTER_BOX) {
        st_pass_stats *ps = st_stats_entry(w, "world", "accumulate");
        w->acc_stats = ps ? (int)(ps - w->stats) : 0;
        if (!ps) ok = st_fail(err, ST_ERR_RUNTIME, "out of memory");
        w->accumulate =
            ok ? st_shader_load("common/fullscreen.vert", "common/accumulate.frag", NULL, err)
               : NULL;
        ok = ok && w->accumulate;
        w->acc_prefill =
            ok ? st_shader_load("common/fullscreen.vert", "common/still_mask.frag", NULL, err)
               : NULL;
        ok = ok && w->acc_prefill;
    }
    if (!ok) {
        st_world_destroy(w);
        return NULL;
    }
    w->cam.current = w->cam.scene.color[0];
    return w;
}

void st_world_destroy(st_world *w) {
    if (!w) return;
    // Teardown order: instances, then each plugin's cleanup, then dlclose.
    for (int m = 0; m < w->num_mods; m++)
        st_world_destroy_instance(w->mods[m]);
    while (w->num_mods)
        st_world_unload(w, w->num_mods - 1);
    st_targets_free(&w->targets, NULL);
    st_graph_free(w);
    st_shader_destroy(w->regular);
    st_shader_destroy(w->background);
    st_model_type_destroy(&w->type);
    st_target_destroy(&w->cam.scene);
    st_target_destroy(&w->cam.post[0]);
    st_target_destroy(&w->cam.post[1]);
    st_target_destroy(&w->cam.accum[0]);
    st_target_destroy(&w->cam.accum[1]);
    st_shader_destroy(w->accumulate);
    st_shader_destroy(w->acc_prefill);
    st_filter_mask_free(w);
    st_medium_gpu_destroy(&w->medium);
    free(w->acc_read);
    free(w->models);
    free(w->stats);
    free(w);
}

// ---- accessors and interactive changes ----------------------------------

const st_scene *st_world_scene(const st_world *w) {
    return w->scene;
}
st_camera *st_world_camera(st_world *w) {
    return &w->cam;
}

const char *st_world_light_defines(const st_world *w) {
    return w->light_defines;
}

void st_world_invalidate(st_world *w, unsigned changes) {
    w->changes |= changes;
}

void st_world_set_camera(st_world *w, const float pos[3], const float target[3],
                         const float up[3]) {
    memcpy(w->cam.position, pos, sizeof w->cam.position);
    memcpy(w->cam.target, target, sizeof w->cam.target);
    memcpy(w->cam.up, up, sizeof w->cam.up);
    st_camera_update(&w->cam);
    w->changes |= ST_CHANGE_CAMERA;
}

bool st_world_resize(st_world *w, int width, int height, st_err *err) {
    if (width == w->cam.width && height == w->cam.height) return true;
    if (width < 1 || height < 1) return st_fail(err, ST_ERR_INPUT, "bad size %dx%d", width, height);
    w->cam.width = width;
    w->cam.height = height;
    st_camera_update(&w->cam);
    w->changes |= ST_CHANGE_SIZE | ST_CHANGE_CAMERA;
    if (!create_targets(w, err)) return false;
    w->cam.current = w->cam.scene.color[0];
    return true;
}

bool st_world_set_light(st_world *w, int i, const float pos[3], const float intensity[3],
                        st_err *err) {
    if (i < 0 || i >= w->num_lights)
        return st_fail(err, ST_ERR_INPUT, "light %d: the scene has %d", i, w->num_lights);
    memcpy(w->light_pos[i], pos, sizeof w->light_pos[i]);
    memcpy(w->light_int[i], intensity, sizeof w->light_int[i]);
    // Modules (shadow_map) read lights from the scene the caller lent the
    // world; it is the caller's, so it follows the move too.
    st_light_desc *l = &((st_scene *)w->scene)->lights[i];
    memcpy(l->position, pos, sizeof l->position);
    memcpy(l->intensity, intensity, sizeof l->intensity);
    st_world_invalidate(w, ST_CHANGE_LIGHTS);
    return true;
}

uint32_t st_world_accumulated(const st_world *w, bool *done) {
    if (done) *done = w->opts.filter == ST_FILTER_BOX && w->acc_done;
    return w->opts.filter == ST_FILTER_BOX ? w->acc_n : 0;
}

int st_world_num_modules(const st_world *w) {
    return w->num_mods;
}
st_module_info st_world_module(const st_world *w, int i) {
    st_module_info mi = {w->mods[i]->p, (double *)w->mods[i]->params};
    return mi;
}
