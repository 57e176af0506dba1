// The scene's owned arrays: adding meshes, lights and module parameters,
// command-line overrides (--set MODULE.PARAM=VALUE), freeing.
#include "st_scene.h"
#include "st_scene_json.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Grows *arr (of elem bytes) so that it holds n + 1 elements; doubling keeps
// appends amortised O(1) for glTF files with thousands of primitives.
static bool grow(void **arr, int *cap, int n, size_t elem) {
    if (n < *cap) return true;
    if (n >= (1 << 30)) return false;
    int nc = n < 8 ? 8 : 2 * n;
    void *p = realloc(*arr, (size_t)nc * elem);
    if (!p) return false;
    *arr = p;
    *cap = nc;
    return true;
}

bool st_scene_add_mesh(st_scene *scene, const st_mesh *mesh, st_err *err) {
    void *arr = scene->meshes;
    if (!grow(&arr, &scene->mesh_capacity, scene->num_meshes, sizeof(st_mesh))) {
        st_mesh copy = *mesh;
        st_mesh_free(&copy);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory adding mesh '%s'", mesh->name);
    }
    scene->meshes = arr;
    scene->meshes[scene->num_meshes++] = *mesh;
    return true;
}

bool st_scene_add_light(st_scene *scene, const st_light_desc *light, st_err *err) {
    void *arr = scene->lights;
    if (!grow(&arr, &scene->light_capacity, scene->num_lights, sizeof(st_light_desc)))
        return st_fail(err, ST_ERR_RUNTIME, "out of memory adding a light");
    scene->lights = arr;
    scene->lights[scene->num_lights++] = *light;
    return true;
}

st_module_setting *st_scene_module(st_scene *scene, const char *name) {
    for (int i = 0; scene && name && i < scene->num_modules; i++)
        if (!strcmp(scene->modules[i].name, name)) return &scene->modules[i];
    return NULL;
}

bool st_module_setting_put(st_module_setting *m, const char *param, const st_value *value,
                           st_err *err) {
    if (!st_j_identifier(param, ST_NAME_MAX))
        return st_fail(err, ST_ERR_INPUT,
                       "%s.%.64s: parameter names are identifiers of 1..%d characters", m->name,
                       param, ST_NAME_MAX - 1);
    for (int i = 0; i < m->num_params; i++) {
        if (!strcmp(m->params[i].name, param)) {
            m->params[i].value = *value;
            m->params[i].set_arg[0] = 0;
            return true;
        }
    }
    st_param_setting *p = realloc(m->params, (size_t)(m->num_params + 1) * sizeof *p);
    if (!p) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    m->params = p;
    memset(&p[m->num_params], 0, sizeof *p);
    snprintf(p[m->num_params].name, ST_NAME_MAX, "%s", param);
    p[m->num_params++].value = *value;
    return true;
}

// VALUE of --set: true/false, a finite number (the whole text), or else a
// string.
static bool parse_value(const char *text, st_value *v, const char *what, st_err *err) {
    memset(v, 0, sizeof *v);
    if (!strcmp(text, "true") || !strcmp(text, "false")) {
        v->type = ST_VALUE_BOOL;
        v->number = text[0] == 't';
        return true;
    }
    char *end = NULL;
    double d = strtod(text, &end);
    if (end != text && *end == 0) {
        if (!isfinite(d))
            return st_fail(err, ST_ERR_INPUT, "--set %s: value is not a finite number", what);
        v->type = ST_VALUE_NUMBER;
        v->number = d;
        return true;
    }
    size_t n = strlen(text);
    if (n == 0) return st_fail(err, ST_ERR_INPUT, "--set %s: empty value", what);
    if (n >= ST_NAME_MAX)
        return st_fail(err, ST_ERR_INPUT, "--set %s: string value longer than %d characters", what,
                       ST_NAME_MAX - 1);
    v->type = ST_VALUE_STRING;
    memcpy(v->str, text, n + 1);
    return true;
}

bool st_scene_set(st_scene *scene, const char *assignment, st_err *err) {
    if (!scene || !assignment)
        return st_fail(err, ST_ERR_INPUT, "--set: missing MODULE.PARAM=VALUE");
    // Shown in messages; long input is cut rather than overflowing err.
    char what[256];
    snprintf(what, sizeof what, "%s", assignment);
    const char *eq = strchr(assignment, '=');
    const char *dot = eq ? memchr(assignment, '.', (size_t)(eq - assignment)) : NULL;
    if (!eq || !dot)
        return st_fail(err, ST_ERR_INPUT, "--set %s: expected MODULE.PARAM=VALUE", what);
    char module[ST_NAME_MAX], param[ST_NAME_MAX];
    size_t mlen = (size_t)(dot - assignment), plen = (size_t)(eq - dot - 1);
    if (mlen >= ST_NAME_MAX || plen >= ST_NAME_MAX)
        return st_fail(err, ST_ERR_INPUT, "--set %s: names are at most %d characters", what,
                       ST_NAME_MAX - 1);
    memcpy(module, assignment, mlen);
    module[mlen] = 0;
    memcpy(param, dot + 1, plen);
    param[plen] = 0;
    if (!st_j_identifier(module, ST_NAME_MAX) || !st_j_identifier(param, ST_NAME_MAX))
        return st_fail(err, ST_ERR_INPUT, "--set %s: MODULE and PARAM must be identifiers", what);
    st_module_setting *m = st_scene_module(scene, module);
    if (!m) {
        char list[256] = "";
        for (int i = 0; i < scene->num_modules; i++) {
            size_t n = strlen(list);
            snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", scene->modules[i].name);
        }
        return st_fail(err, ST_ERR_INPUT,
                       "--set %s: module '%s' is not in the scene (it loads: %s)", what, module,
                       list[0] ? list : "no modules");
    }
    st_value v;
    if (!parse_value(eq + 1, &v, what, err)) return false;
    if (!st_module_setting_put(m, param, &v, err)) return false;
    // Remembered so that a later range check blames the --set, not the scene file.
    for (int i = 0; i < m->num_params; i++)
        if (!strcmp(m->params[i].name, param))
            snprintf(m->params[i].set_arg, sizeof m->params[i].set_arg, "%.127s", what);
    return true;
}

uint64_t st_scene_triangle_count(const st_scene *scene) {
    uint64_t n = 0;
    for (int i = 0; scene && i < scene->num_meshes; i++)
        n += scene->meshes[i].num_triangles;
    return n;
}

bool st_scene_bounds(const st_scene *scene, double lo[3], double hi[3]) {
    bool any = false;
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (int i = 0; scene && i < scene->num_meshes; i++) {
        const st_mesh *m = &scene->meshes[i];
        const float *M = m->model; // column major
        for (uint32_t v = 0; v < m->num_vertices; v++) {
            const float *p = m->positions + 3 * (size_t)v;
            for (int k = 0; k < 3; k++) {
                double w = (double)M[k] * p[0] + (double)M[4 + k] * p[1] + (double)M[8 + k] * p[2] +
                           M[12 + k];
                lo[k] = fmin(lo[k], w), hi[k] = fmax(hi[k], w);
            }
            any = true;
        }
    }
    return any;
}

st_camera_desc st_scene_auto_camera(const double lo[3], const double hi[3]) {
    // A three-quarter view: from +z (glTF's front), a little from +x and above.
    static const double dir[3] = {0.42, 0.36, 0.83}; // unit length to 3 digits
    double c[3], r2 = 0;
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        r2 += 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    double r = fmax(sqrt(r2), 1e-3), fov = 50.0;
    // The bounding sphere fits the vertical field of view with 5% to spare.
    double dist = 1.05 * r / sin(0.5 * fov * 3.14159265358979323846 / 180.0);
    st_camera_desc cam = {.up = {0, 1, 0}, .fov_y = (float)fov};
    for (int k = 0; k < 3; k++) {
        cam.target[k] = (float)c[k];
        cam.position[k] = (float)(c[k] + dist * dir[k]);
    }
    cam.near_z = (float)fmax(0.01 * dist, 1e-4 * r);
    cam.far_z = (float)(2.0 * (dist + r));
    return cam;
}

void st_scene_free(st_scene *scene) {
    if (!scene) return;
    for (int i = 0; i < scene->num_meshes; i++)
        st_mesh_free(&scene->meshes[i]);
    free(scene->meshes);
    free(scene->lights);
    for (int i = 0; i < scene->num_modules; i++)
        free(scene->modules[i].params);
    free(scene->modules);
    st_density_grid_free(scene->density.grid);
    free(scene->density.grid);
    st_scene_files_free(scene);
    memset(scene, 0, sizeof *scene);
}
