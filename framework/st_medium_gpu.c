// strahl: the medium's varying density on the GPU (see st_medium_gpu.h).
#include "st_medium_gpu.h"
#include "st_physics.h"
#include <stdio.h>
#include <string.h>

// Modules whose shaders go through the density API of common/medium.glsl
// (or use no medium at all). The others march or bounce through a
// homogeneous medium and would draw a wrong image without a word.
static const char *const density_modules[] = {"shadow_map", "toth", "froxel", NULL};

bool st_medium_gpu_module_ok(const char *name) {
    for (int i = 0; density_modules[i]; i++)
        if (!strcmp(name, density_modules[i])) return true;
    return false;
}

static bool varies(const st_scene *s) {
    return s->medium.present && st_density_varies(&s->density);
}

bool st_medium_gpu_check_module(const st_scene *s, const char *name, st_err *err) {
    if (!varies(s) || st_medium_gpu_module_ok(name)) return true;
    return st_fail(err, ST_ERR_INPUT,
                   "%s: medium.density (%s): module '%s' models a homogeneous medium only; with a "
                   "varying density the GPU runs shadow_map, toth and froxel",
                   s->path, s->density.kind == ST_DENSITY_HEIGHT ? "height fog" : "vdb grid", name);
}

void st_medium_gpu_defines(const st_scene *s, char *defines, size_t cap) {
    if (!varies(s)) return;
    size_t n = strlen(defines);
    if (n < cap) snprintf(defines + n, cap - n, "ST_DENSITY %d\n", (int)s->density.kind);
}

// world -> local index coordinates u = to_index x - lo (C: grid_local), as
// a column-major mat4.
static void grid_matrix(const st_density_grid *g, float out[16]) {
    memset(out, 0, 16 * sizeof *out);
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            out[4 * c + r] = (float)g->to_index[4 * r + c];
        out[12 + r] = (float)(g->to_index[4 * r + 3] - g->lo[r]);
    }
    out[15] = 1.0f;
}

static bool upload_grid(st_medium_gpu *m, const st_density_grid *g, const char *path, st_err *err) {
    GLint max = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max);
    if (g->n[0] > max || g->n[1] > max || g->n[2] > max)
        return st_fail(err, ST_ERR_RUNTIME,
                       "%s: medium.density: a %dx%dx%d grid exceeds the GPU's 3D texture size %d",
                       path, g->n[0], g->n[1], g->n[2], max);
    glGenTextures(1, &m->grid);
    glBindTexture(GL_TEXTURE_3D, m->grid);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_R32F, g->n[0], g->n[1], g->n[2], 0, GL_RED, GL_FLOAT,
                 g->values);
    // Read with texelFetch only (the shader interpolates like C), so no
    // filtering and no mipmaps.
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAX_LEVEL, 0);
    glBindTexture(GL_TEXTURE_3D, 0);
    glObjectLabel(GL_TEXTURE, m->grid, -1, "medium.density");
    memcpy(m->size, g->n, sizeof m->size);
    grid_matrix(g, m->to_local);
    return st_gl_check("medium.density grid upload", err);
}

bool st_medium_gpu_create(st_medium_gpu *m, const st_scene *s, st_err *err) {
    memset(m, 0, sizeof *m);
    if (!varies(s)) return true;
    for (int i = 0; i < s->num_modules; i++)
        if (!st_medium_gpu_check_module(s, s->modules[i].name, err)) return false;
    m->kind = s->density.kind;
    m->base = (float)s->density.base;
    m->falloff = (float)s->density.falloff;
    if (m->kind == ST_DENSITY_GRID && !upload_grid(m, s->density.grid, s->path, err)) {
        st_medium_gpu_destroy(m);
        return false;
    }
    return true;
}

void st_medium_gpu_destroy(st_medium_gpu *m) {
    if (m->grid) glDeleteTextures(1, &m->grid);
    memset(m, 0, sizeof *m);
}

void st_medium_gpu_uniforms(const st_medium_gpu *m, st_shader *sh) {
    switch (m->kind) {
    case ST_DENSITY_HEIGHT:
        st_shader_set_float(sh, "st_density_base", m->base);
        st_shader_set_float(sh, "st_density_falloff", m->falloff);
        break;
    case ST_DENSITY_GRID: {
        st_shader_texture(sh, "st_density_grid", GL_TEXTURE_3D, m->grid);
        st_shader_set_mat4(sh, "st_density_to_local", m->to_local);
        GLint l = st_shader_loc(sh, "st_density_size");
        if (l >= 0) glUniform3iv(l, 1, m->size);
        break;
    }
    case ST_DENSITY_UNIFORM:
    default:
        break;
    }
}
