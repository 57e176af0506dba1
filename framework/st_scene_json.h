// strahl: strict readers of cJSON values for the scene parser (private to
// st_scene*.c). Each reader names the offending key path in its error:
// "scenes/x.json: geometry[2].quad.u: expected an array of 3 numbers".
#ifndef ST_SCENE_JSON_H
#define ST_SCENE_JSON_H
#include "st_base.h"
#include <cjson/cJSON.h>

// Internal to libstrahl: not exported.
#pragma GCC visibility push(hidden)

typedef struct st_jctx {
    const char *file; // named first in every message
    st_err *err;
    char path[512]; // current key path, e.g. "geometry[2].quad"
    size_t len;
    unsigned flags; // st_scene_opts.flags (ST_ASSETS_*)
} st_jctx;

// Path bookkeeping: push returns a mark that pop restores.
size_t st_j_push(st_jctx *c, const char *key);
size_t st_j_push_index(st_jctx *c, int index);
void st_j_pop(st_jctx *c, size_t mark);

// Fails with "<file>: <path>[.key]: <problem>"; key may be NULL. Returns false.
bool st_j_fail(st_jctx *c, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

// Checks that v is an object whose keys are all in `allowed` (NULL-terminated;
// NULL allows any key) and appear once. Errors name the current path.
bool st_j_object(st_jctx *c, const cJSON *v, const char *const *allowed);
const cJSON *st_j_get(const cJSON *obj, const char *key);

// Field readers: obj[key] must have the right type. A missing key fails when
// `present` is NULL (required) and sets *present = false otherwise, leaving
// *out untouched.
bool st_j_number(st_jctx *c, const cJSON *obj, const char *key, double *out, bool *present);
bool st_j_float(st_jctx *c, const cJSON *obj, const char *key, float *out, bool *present);
bool st_j_int(st_jctx *c, const cJSON *obj, const char *key, int lo, int hi, int *out,
              bool *present);
bool st_j_bool(st_jctx *c, const cJSON *obj, const char *key, bool *out, bool *present);
bool st_j_string(st_jctx *c, const cJSON *obj, const char *key, char *out, size_t cap,
                 bool *present);
bool st_j_vec3(st_jctx *c, const cJSON *obj, const char *key, float out[3], bool *present);
// Every component in [lo, hi]; the error names key.
bool st_j_range3(st_jctx *c, const char *key, const float v[3], float lo, float hi);

// True for non-empty [A-Za-z_][A-Za-z0-9_]* shorter than max.
bool st_j_identifier(const char *s, size_t max);

// The "geometry" section (st_scene_geometry.c); c's path names the array.
// *has_camera is set when a glTF file supplied the scene camera.
struct st_scene;
bool st_scene_parse_geometry(st_jctx *c, const cJSON *arr, struct st_scene *s, bool *has_camera);

#pragma GCC visibility pop

#endif
