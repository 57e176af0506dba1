// Strict cJSON readers for the scene parser: exact types, finite numbers,
// fixed-length arrays, no unknown or repeated keys, and a key path in every
// message.
#include "st_scene_json.h"
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

// Appends s to the path, replacing control characters (keys come from the
// input and end up in a terminal) and truncating at the buffer end.
static void path_append(st_jctx *c, const char *s) {
    for (; *s && c->len + 1 < sizeof c->path; s++)
        c->path[c->len++] = ((unsigned char)*s < 0x20 || *s == 0x7f) ? '?' : *s;
    c->path[c->len] = 0;
}

size_t st_j_push(st_jctx *c, const char *key) {
    size_t mark = c->len;
    if (c->len) path_append(c, ".");
    path_append(c, key);
    return mark;
}

size_t st_j_push_index(st_jctx *c, int index) {
    size_t mark = c->len;
    char b[24];
    snprintf(b, sizeof b, "[%d]", index);
    path_append(c, b);
    return mark;
}

void st_j_pop(st_jctx *c, size_t mark) {
    c->len = mark;
    c->path[mark] = 0;
}

bool st_j_fail(st_jctx *c, const char *key, const char *fmt, ...) {
    char problem[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(problem, sizeof problem, fmt, ap);
    va_end(ap);
    size_t mark = key ? st_j_push(c, key) : c->len;
    if (c->len)
        st_fail(c->err, ST_ERR_INPUT, "%s: %s: %s", c->file, c->path, problem);
    else
        st_fail(c->err, ST_ERR_INPUT, "%s: %s", c->file, problem);
    st_j_pop(c, mark);
    return false;
}

const cJSON *st_j_get(const cJSON *obj, const char *key) {
    return cJSON_GetObjectItemCaseSensitive(obj, key);
}

static const char *type_name(const cJSON *v) {
    if (cJSON_IsNumber(v)) return "a number";
    if (cJSON_IsBool(v)) return "a boolean";
    if (cJSON_IsString(v)) return "a string";
    if (cJSON_IsArray(v)) return "an array";
    if (cJSON_IsObject(v)) return "an object";
    if (cJSON_IsNull(v)) return "null";
    return "an invalid value";
}

bool st_j_object(st_jctx *c, const cJSON *v, const char *const *allowed) {
    if (!cJSON_IsObject(v)) return st_j_fail(c, NULL, "expected an object, got %s", type_name(v));
    for (const cJSON *it = v->child; it; it = it->next) {
        const char *k = it->string ? it->string : "";
        bool ok = !allowed;
        for (int i = 0; allowed && allowed[i]; i++)
            ok = ok || !strcmp(allowed[i], k);
        if (!ok) {
            char list[256] = "";
            for (int i = 0; allowed[i]; i++) {
                size_t n = strlen(list);
                snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", allowed[i]);
            }
            return st_j_fail(c, k, "unknown key (expected one of: %s)", list);
        }
        for (const cJSON *p = v->child; p != it; p = p->next)
            if (p->string && !strcmp(p->string, k)) return st_j_fail(c, k, "key given twice");
    }
    return true;
}

// Looks obj[key] up; handles the missing case. Returns the item or NULL with
// *ok telling whether NULL is an error.
static const cJSON *field(st_jctx *c, const cJSON *obj, const char *key, bool *present, bool *ok) {
    const cJSON *v = st_j_get(obj, key);
    *ok = true;
    if (present) *present = v != NULL;
    if (!v && !present) *ok = st_j_fail(c, key, "required key missing");
    return v;
}

static bool finite_number(st_jctx *c, const char *key, const cJSON *v, double *out) {
    if (!cJSON_IsNumber(v)) return st_j_fail(c, key, "expected a number, got %s", type_name(v));
    // cJSON turns 1e999 into inf; JSON has no NaN but guard anyway.
    if (!isfinite(v->valuedouble)) return st_j_fail(c, key, "number is not finite");
    *out = v->valuedouble;
    return true;
}

bool st_j_number(st_jctx *c, const cJSON *obj, const char *key, double *out, bool *present) {
    bool ok;
    const cJSON *v = field(c, obj, key, present, &ok);
    return v ? finite_number(c, key, v, out) : ok;
}

static bool to_float(st_jctx *c, const char *key, double d, float *out) {
    if (fabs(d) > FLT_MAX) return st_j_fail(c, key, "%.9g is out of range for a 32-bit float", d);
    // A value that would become 0 is reported as written, not as "got 0".
    if (d != 0 && (float)d == 0)
        return st_j_fail(c, key, "%.9g is too small for a 32-bit float (it would be 0)", d);
    *out = (float)d;
    return true;
}

bool st_j_float(st_jctx *c, const cJSON *obj, const char *key, float *out, bool *present) {
    bool ok;
    double d = 0;
    const cJSON *v = field(c, obj, key, present, &ok);
    if (!v) return ok;
    return finite_number(c, key, v, &d) && to_float(c, key, d, out);
}

bool st_j_int(st_jctx *c, const cJSON *obj, const char *key, int lo, int hi, int *out,
              bool *present) {
    bool ok;
    double d = 0;
    const cJSON *v = field(c, obj, key, present, &ok);
    if (!v) return ok;
    if (!finite_number(c, key, v, &d)) return false;
    if (d != floor(d)) return st_j_fail(c, key, "expected an integer, got %.9g", d);
    if (d < lo || d > hi) return st_j_fail(c, key, "%.9g is out of range [%d, %d]", d, lo, hi);
    *out = (int)d;
    return true;
}

bool st_j_bool(st_jctx *c, const cJSON *obj, const char *key, bool *out, bool *present) {
    bool ok;
    const cJSON *v = field(c, obj, key, present, &ok);
    if (!v) return ok;
    if (!cJSON_IsBool(v)) return st_j_fail(c, key, "expected true or false, got %s", type_name(v));
    *out = cJSON_IsTrue(v);
    return true;
}

bool st_j_string(st_jctx *c, const cJSON *obj, const char *key, char *out, size_t cap,
                 bool *present) {
    bool ok;
    const cJSON *v = field(c, obj, key, present, &ok);
    if (!v) return ok;
    if (!cJSON_IsString(v) || !v->valuestring)
        return st_j_fail(c, key, "expected a string, got %s", type_name(v));
    size_t n = strlen(v->valuestring);
    if (n == 0) return st_j_fail(c, key, "empty string");
    if (n >= cap) return st_j_fail(c, key, "string longer than %zu characters", cap - 1);
    // Strings reach messages (names, paths): no escape sequence for the terminal.
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)v->valuestring[i] < 0x20 || v->valuestring[i] == 0x7f)
            return st_j_fail(c, key, "contains the control character 0x%02x at offset %zu",
                             (unsigned char)v->valuestring[i], i);
    memcpy(out, v->valuestring, n + 1);
    return true;
}

bool st_j_vec3(st_jctx *c, const cJSON *obj, const char *key, float out[3], bool *present) {
    bool ok;
    const cJSON *v = field(c, obj, key, present, &ok);
    if (!v) return ok;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
        return st_j_fail(c, key, "expected an array of 3 numbers");
    float tmp[3];
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        if (!cJSON_IsNumber(e)) return st_j_fail(c, key, "expected an array of 3 numbers");
        if (!isfinite(e->valuedouble)) return st_j_fail(c, key, "element %d is not finite", i);
        if (!to_float(c, key, e->valuedouble, &tmp[i])) return false;
    }
    memcpy(out, tmp, sizeof tmp);
    return true;
}

bool st_j_range3(st_jctx *c, const char *key, const float v[3], float lo, float hi) {
    for (int i = 0; i < 3; i++) {
        if (v[i] < lo || v[i] > hi) {
            if (hi == INFINITY)
                return st_j_fail(c, key, "element %d is %g, expected >= %g", i, v[i], lo);
            return st_j_fail(c, key, "element %d is %g, expected a value in [%g, %g]", i, v[i], lo,
                             hi);
        }
    }
    return true;
}

bool st_j_identifier(const char *s, size_t max) {
    size_t n = 0;
    for (; s[n]; n++) {
        char ch = s[n];
        bool alpha = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_';
        if (!alpha && !(n > 0 && ch >= '0' && ch <= '9')) return false;
    }
    return n > 0 && n < max;
}
