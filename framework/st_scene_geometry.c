// The scene's "geometry" array: each entry is exactly one of gltf, box, quad
// or sphere, with optional albedo, emission and double_sided (which override
// a glTF file's materials).
#include "st_scene.h"
#include "st_scene_json.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct material {
    float albedo[3], emission[3];
    bool double_sided;
    bool has_albedo, has_emission, has_double_sided;
} material;

static bool budget(st_jctx *c, const st_scene *s, uint64_t more) {
    uint64_t have = st_scene_triangle_count(s);
    if (have + more > ST_SCENE_MAX_TRIANGLES)
        return st_j_fail(
            c, NULL, "the scene would have %llu triangles, more than the limit of %llu",
            (unsigned long long)(have + more), (unsigned long long)ST_SCENE_MAX_TRIANGLES);
    return true;
}

// Applies the entry's material and appends a freshly built procedural mesh.
static bool add_shape(st_jctx *c, st_scene *s, st_mesh *m, const char *kind, int index,
                      const material *mat) {
    if (!m->positions)
        return st_fail(c->err, ST_ERR_RUNTIME, "%s: %s: out of memory", c->file, c->path);
    // Huge but finite inputs can still overflow float when added up.
    for (size_t i = 0; i < 3 * (size_t)m->num_vertices; i++) {
        if (!isfinite(m->positions[i]) || !isfinite(m->normals[i])) {
            st_mesh_free(m);
            return st_j_fail(c, NULL, "coordinates overflow 32-bit floats");
        }
    }
    snprintf(m->name, sizeof m->name, "geometry[%d].%s", index, kind);
    memcpy(m->albedo, mat->albedo, sizeof m->albedo);
    memcpy(m->emission, mat->emission, sizeof m->emission);
    m->double_sided = mat->double_sided;
    if (!st_scene_add_mesh(s, m, c->err)) {
        st_err_prefix(c->err, "%s: %s: ", c->file, c->path);
        return false;
    }
    return true;
}

static double len3(const double v[3]) {
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static bool parse_box(st_jctx *c, const cJSON *v, bool inward, st_scene *s, int index,
                      const material *mat) {
    static const char *const keys[] = {"min", "max", NULL};
    float mn[3], mx[3];
    if (!st_j_object(c, v, keys) || !st_j_vec3(c, v, "min", mn, NULL) ||
        !st_j_vec3(c, v, "max", mx, NULL))
        return false;
    for (int k = 0; k < 3; k++)
        if (!(mx[k] > mn[k]))
            return st_j_fail(c, NULL, "zero or negative volume: max.%c must exceed min.%c",
                             "xyz"[k], "xyz"[k]);
    if (!budget(c, s, 12)) return false;
    st_mesh m;
    st_mesh_box(&m, mn, mx, inward);
    return add_shape(c, s, &m, "box", index, mat);
}

static bool parse_quad(st_jctx *c, const cJSON *v, st_scene *s, int index, const material *mat) {
    static const char *const keys[] = {"corner", "u", "v", NULL};
    float p[3], u[3], w[3];
    if (!st_j_object(c, v, keys) || !st_j_vec3(c, v, "corner", p, NULL) ||
        !st_j_vec3(c, v, "u", u, NULL) || !st_j_vec3(c, v, "v", w, NULL))
        return false;
    double du[3] = {u[0], u[1], u[2]}, dv[3] = {w[0], w[1], w[2]};
    double n[3] = {du[1] * dv[2] - du[2] * dv[1], du[2] * dv[0] - du[0] * dv[2],
                   du[0] * dv[1] - du[1] * dv[0]};
    if (len3(du) == 0) return st_j_fail(c, "u", "zero-length edge");
    if (len3(dv) == 0) return st_j_fail(c, "v", "zero-length edge");
    // Relative test: parallel edges give |u x v| at rounding level.
    if (!(len3(n) > 1e-12 * len3(du) * len3(dv)))
        return st_j_fail(c, NULL, "u and v are parallel (zero area)");
    if (!budget(c, s, 2)) return false;
    st_mesh m;
    st_mesh_quad(&m, p, u, w);
    return add_shape(c, s, &m, "quad", index, mat);
}

static bool parse_sphere(st_jctx *c, const cJSON *v, st_scene *s, int index, const material *mat) {
    static const char *const keys[] = {"center", "radius", "rings", "segments", NULL};
    float center[3], radius;
    int rings = 32, segments = 64;
    bool has;
    if (!st_j_object(c, v, keys) || !st_j_vec3(c, v, "center", center, NULL) ||
        !st_j_float(c, v, "radius", &radius, NULL) ||
        !st_j_int(c, v, "rings", 2, 16384, &rings, &has) ||
        !st_j_int(c, v, "segments", 3, 16384, &segments, &has))
        return false;
    if (!(radius > 0)) return st_j_fail(c, "radius", "expected > 0, got %g", radius);
    if (!budget(c, s, 2ull * (uint64_t)segments * (uint64_t)(rings - 1))) return false;
    st_mesh m;
    st_mesh_sphere(&m, center, radius, rings, segments);
    return add_shape(c, s, &m, "sphere", index, mat);
}

static bool parse_gltf(st_jctx *c, const cJSON *entry, st_scene *s, bool *has_camera,
                       const material *mat) {
    char rel[4096], full[8192];
    if (!st_j_string(c, entry, "gltf", rel, sizeof rel, NULL)) return false;
    st_path_join(full, sizeof full, s->dir, rel);
    int first = s->num_meshes;
    if (!st_gltf_load_ex(full, c->flags, s, has_camera, c->err)) {
        st_err_prefix(c->err, "%s: %s.gltf: ", c->file, c->path);
        return false;
    }
    for (int i = first; i < s->num_meshes; i++) {
        st_mesh *m = &s->meshes[i];
        if (mat->has_albedo) memcpy(m->albedo, mat->albedo, sizeof m->albedo);
        if (mat->has_emission) memcpy(m->emission, mat->emission, sizeof m->emission);
        if (mat->has_double_sided) m->double_sided = mat->double_sided;
    }
    return true;
}

static bool parse_entry(st_jctx *c, const cJSON *e, int index, st_scene *s, bool *has_camera) {
    static const char *const keys[] = {"gltf",     "box",          "quad",   "sphere", "albedo",
                                       "emission", "double_sided", "inward", NULL};
    static const char *const shapes[] = {"gltf", "box", "quad", "sphere"};
    if (!st_j_object(c, e, keys)) return false;
    int shape = -1;
    for (int k = 0; k < 4; k++) {
        if (!st_j_get(e, shapes[k])) continue;
        if (shape >= 0)
            return st_j_fail(c, NULL, "has both '%s' and '%s'; an entry is exactly one shape",
                             shapes[shape], shapes[k]);
        shape = k;
    }
    if (shape < 0) return st_j_fail(c, NULL, "expected one of the keys gltf, box, quad, sphere");

    material mat = {.albedo = {0.75f, 0.75f, 0.75f}};
    bool inward = false, has_inward;
    if (!st_j_vec3(c, e, "albedo", mat.albedo, &mat.has_albedo) ||
        (mat.has_albedo && !st_j_range3(c, "albedo", mat.albedo, 0, 1)) ||
        !st_j_vec3(c, e, "emission", mat.emission, &mat.has_emission) ||
        (mat.has_emission && !st_j_range3(c, "emission", mat.emission, 0, INFINITY)) ||
        !st_j_bool(c, e, "double_sided", &mat.double_sided, &mat.has_double_sided) ||
        !st_j_bool(c, e, "inward", &inward, &has_inward))
        return false;
    if (has_inward && shape != 1) return st_j_fail(c, "inward", "only valid for a box");

    if (shape == 0) return parse_gltf(c, e, s, has_camera, &mat);
    size_t mark = st_j_push(c, shapes[shape]);
    const cJSON *v = st_j_get(e, shapes[shape]);
    bool ok = shape == 1   ? parse_box(c, v, inward, s, index, &mat)
              : shape == 2 ? parse_quad(c, v, s, index, &mat)
                           : parse_sphere(c, v, s, index, &mat);
    st_j_pop(c, mark);
    return ok;
}

bool st_scene_parse_geometry(st_jctx *c, const cJSON *arr, st_scene *s, bool *has_camera) {
    if (!cJSON_IsArray(arr)) return st_j_fail(c, NULL, "expected an array");
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        size_t mark = st_j_push_index(c, i);
        bool ok = parse_entry(c, e, i, s, has_camera);
        st_j_pop(c, mark);
        if (!ok) return false;
    }
    return true;
}
