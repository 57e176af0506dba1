// Targets owned by the world and objects tracked by name: thin wrappers
// over the registry (st_targets.c) at the camera's size.
#include "st_world_state.h"

bool st_world_declare_target(st_world *w, const char *name, const st_target_desc *d, st_err *err) {
    return st_targets_declare(&w->targets, name, d, err);
}

const st_target *st_world_get_target(st_world *w, const char *name, st_err *err) {
    int i = st_targets_find(&w->targets, name);
    if (i < 0) {
        st_fail(err, ST_ERR_RUNTIME, "target '%s' was not declared", name);
        return NULL;
    }
    if (!st_targets_ensure(&w->targets, i, w->cam.width, w->cam.height, err)) return NULL;
    return &w->targets.t[i].t;
}

const st_target *st_world_alloc_target(st_world *w, const char *name, const st_target_desc *d,
                                       st_err *err) {
    return st_world_declare_target(w, name, d, err) ? st_world_get_target(w, name, err) : NULL;
}

const st_target *st_world_target(st_world *w, const char *name) {
    st_err ignore = {0};
    return st_world_get_target(w, name, &ignore);
}

bool st_world_track(st_world *w, const char *name, GLenum identifier, GLuint obj, st_err *err) {
    return st_targets_track(&w->targets, name, identifier, obj, err);
}

void st_world_untrack(st_world *w, const char *name) {
    st_targets_untrack(&w->targets, name);
}

GLuint st_world_buffer(st_world *w, const char *name, size_t bytes, const void *data, st_err *err) {
    return st_targets_buffer(&w->targets, name, bytes, data, err);
}

GLuint st_world_buffer_texture(st_world *w, const char *name, GLuint buf, GLenum format,
                               st_err *err) {
    return st_targets_buffer_texture(&w->targets, name, buf, format, err);
}
