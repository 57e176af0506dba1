// Scene description v1 (README.md "Scene description"): strict JSON parsing
// into st_scene. Sections are read in an order that lets the JSON override
// what glTF files bring: geometry (may supply camera and lights) before camera
// and the final choice of lights.
#include "st_scene.h"
#include "st_file.h"
#include "st_scene_json.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *st_filter_name(st_pixel_filter f) {
    return f == ST_FILTER_BOX ? "box" : "point";
}

bool st_filter_parse(const char *s, st_pixel_filter *out) {
    if (!strcmp(s, "box"))
        *out = ST_FILTER_BOX;
    else if (!strcmp(s, "point"))
        *out = ST_FILTER_POINT;
    else
        return false;
    return true;
}

static bool parse_image(st_jctx *c, const cJSON *v, st_scene *s) {
    static const char *const keys[] = {"width", "height", "filter", NULL};
    bool has;
    char filter[64] = "";
    if (!st_j_object(c, v, keys) || !st_j_int(c, v, "width", 1, 16384, &s->width, &has) ||
        !st_j_int(c, v, "height", 1, 16384, &s->height, &has) ||
        !st_j_string(c, v, "filter", filter, sizeof filter, &has))
        return false;
    if (has && !st_filter_parse(filter, &s->filter))
        return st_j_fail(c, "filter", "'%s' is not a pixel filter (box or point)", filter);
    return true;
}

// A unit direction from "direction" (must not be zero).
static bool parse_direction(st_jctx *c, const cJSON *v, float out[3]) {
    if (!st_j_vec3(c, v, "direction", out, NULL)) return false;
    double l = sqrt((double)out[0] * out[0] + (double)out[1] * out[1] + (double)out[2] * out[2]);
    if (!(l > 1e-12) || !isfinite(l)) return st_j_fail(c, "direction", "must be a non-zero vector");
    for (int k = 0; k < 3; k++)
        out[k] = (float)(out[k] / l);
    return true;
}

// Spot cone half-angles in degrees (glTF's innerConeAngle/outerConeAngle,
// defaults 0 and 45): 0 <= inner < outer <= 90.
static bool parse_cone(st_jctx *c, const cJSON *v, st_light_desc *l) {
    double inner = 0, outer = 45;
    bool has;
    if (!st_j_number(c, v, "inner_angle", &inner, &has) ||
        !st_j_number(c, v, "outer_angle", &outer, &has))
        return false;
    if (!(outer > 0 && outer <= 90))
        return st_j_fail(c, "outer_angle", "%.9g is out of range (0, 90] degrees", outer);
    if (!(inner >= 0 && inner < outer))
        return st_j_fail(c, "inner_angle", "%g must be in [0, outer_angle = %g) degrees", inner,
                         outer);
    l->inner_angle = (float)(inner * 3.14159265358979323846 / 180.0);
    l->outer_angle = (float)(outer * 3.14159265358979323846 / 180.0);
    return true;
}

// The sun's disc for screen-space god rays, degrees: (0, 30], default 0.53.
static bool parse_angular_diameter(st_jctx *c, const cJSON *v, st_light_desc *l) {
    double deg = 0.53;
    bool has;
    if (!st_j_number(c, v, "angular_diameter", &deg, &has)) return false;
    if (!(deg > 0 && deg <= 30))
        return st_j_fail(c, "angular_diameter", "%.9g is out of range (0, 30] degrees", deg);
    l->angular_diameter = (float)(deg * 3.14159265358979323846 / 180.0);
    return true;
}

float st_light_angular_diameter(const st_light_desc *l) {
    return l->angular_diameter > 0 ? l->angular_diameter : ST_SUN_ANGULAR_DIAMETER;
}

static bool parse_light(st_jctx *c, const cJSON *v, st_scene *s) {
    static const char *const point_keys[] = {"type", "position", "intensity", NULL};
    static const char *const dir_keys[] = {"type", "direction", "irradiance", "angular_diameter",
                                           NULL};
    static const char *const spot_keys[] = {"type",        "position",    "direction", "intensity",
                                            "inner_angle", "outer_angle", NULL};
    char type[16];
    st_light_desc l = {0};
    if (!cJSON_IsObject(v)) return st_j_fail(c, NULL, "expected an object");
    if (!st_j_string(c, v, "type", type, sizeof type, NULL)) return false;
    bool ok;
    if (!strcmp(type, "point")) {
        ok = st_j_object(c, v, point_keys) && st_j_vec3(c, v, "position", l.position, NULL) &&
             st_j_vec3(c, v, "intensity", l.intensity, NULL) &&
             st_j_range3(c, "intensity", l.intensity, 0, INFINITY);
    } else if (!strcmp(type, "directional")) {
        l.type = ST_LIGHT_DIRECTIONAL;
        ok = st_j_object(c, v, dir_keys) && parse_direction(c, v, l.direction) &&
             st_j_vec3(c, v, "irradiance", l.intensity, NULL) &&
             st_j_range3(c, "irradiance", l.intensity, 0, INFINITY) &&
             parse_angular_diameter(c, v, &l);
    } else if (!strcmp(type, "spot")) {
        l.type = ST_LIGHT_SPOT;
        ok = st_j_object(c, v, spot_keys) && st_j_vec3(c, v, "position", l.position, NULL) &&
             parse_direction(c, v, l.direction) &&
             st_j_vec3(c, v, "intensity", l.intensity, NULL) &&
             st_j_range3(c, "intensity", l.intensity, 0, INFINITY) && parse_cone(c, v, &l);
    } else {
        return st_j_fail(c, "type", "'%s': expected \"point\", \"directional\" or \"spot\"", type);
    }
    return ok && st_scene_add_light(s, &l, c->err);
}

const char *st_light_type_name(st_light_type type) {
    switch (type) {
    case ST_LIGHT_POINT:
        return "point";
    case ST_LIGHT_DIRECTIONAL:
        return "directional";
    case ST_LIGHT_SPOT:
        return "spot";
    default:
        return "unknown";
    }
}

static bool parse_lights(st_jctx *c, const cJSON *v, st_scene *s) {
    if (!cJSON_IsArray(v)) return st_j_fail(c, NULL, "expected an array");
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        size_t mark = st_j_push_index(c, i);
        bool ok = parse_light(c, e, s);
        st_j_pop(c, mark);
        if (!ok) return false;
    }
    return true;
}

static bool parse_phase(st_jctx *c, const cJSON *v, st_medium_desc *m) {
    static const char *const keys[] = {"hg", NULL};
    if (cJSON_IsString(v) && !strcmp(v->valuestring, "isotropic")) {
        m->phase = ST_PHASE_ISOTROPIC;
        return true;
    }
    if (cJSON_IsString(v) && !strcmp(v->valuestring, "rayleigh")) {
        m->phase = ST_PHASE_RAYLEIGH;
        return true;
    }
    if (!cJSON_IsObject(v))
        return st_j_fail(c, NULL, "expected \"isotropic\", \"rayleigh\" or {\"hg\": g}");
    double g;
    if (!st_j_object(c, v, keys) || !st_j_number(c, v, "hg", &g, NULL)) return false;
    if (g < -1 || g > 1) return st_j_fail(c, "hg", "%.9g is out of range [-1, 1]", g);
    // |g| = 1 is a delta distribution; the phase function's normalisation
    // needs |g| < 1 (docs/physics.md: clamp to 0.999).
    m->phase = ST_PHASE_HG;
    m->g = (float)fmax(-0.999, fmin(0.999, g));
    return true;
}

// medium.density.height: {"base": y0, "falloff": k}, density e^(-k (y - y0)).
// k >= 0 (a negative falloff grows without bound upward: no finite majorant
// along a ray to the sky) and at most 1e4/m; base finite.
static bool parse_height_fog(st_jctx *c, const cJSON *v, st_density_desc *d) {
    static const char *const keys[] = {"base", "falloff", NULL};
    if (!st_j_object(c, v, keys) || !st_j_number(c, v, "base", &d->base, NULL) ||
        !st_j_number(c, v, "falloff", &d->falloff, NULL))
        return false;
    if (!(d->falloff >= 0 && d->falloff <= 1e4))
        return st_j_fail(c, "falloff", "%g is out of range [0, 1e4] (1/m)", d->falloff);
    if (!(fabs(d->base) <= 1e6))
        return st_j_fail(c, "base", "%g is out of range [-1e6, 1e6] (m)", d->base);
    d->kind = ST_DENSITY_HEIGHT;
    return true;
}

// medium.density {"vdb": FILE, "grid": NAME, "transform": {"translate": [x, y, z],
// "scale": [sx, sy, sz]}}: the file resolves against the scene's folder; the
// transform (both keys optional) follows the grid's own index-to-world map.
static bool parse_vdb(st_jctx *c, const cJSON *v, st_scene *s) {
    static const char *const keys[] = {"vdb", "grid", "transform", NULL};
    static const char *const tkeys[] = {"translate", "scale", NULL};
    char rel[4096], full[8192], grid[ST_NAME_MAX] = "density";
    bool has;
    if (!st_j_object(c, v, keys) || !st_j_string(c, v, "vdb", rel, sizeof rel, NULL) ||
        !st_j_string(c, v, "grid", grid, sizeof grid, &has))
        return false;
    float t[3] = {0, 0, 0}, sc[3] = {1, 1, 1};
    const cJSON *tr = st_j_get(v, "transform");
    if (tr) {
        size_t mark = st_j_push(c, "transform");
        bool ok = st_j_object(c, tr, tkeys) && st_j_vec3(c, tr, "translate", t, &has) &&
                  st_j_vec3(c, tr, "scale", sc, &has);
        for (int k = 0; ok && k < 3; k++)
            if (!(fabsf(sc[k]) > 0))
                ok = st_j_fail(c, "scale", "element %d is 0, expected a non-zero factor", k);
        st_j_pop(c, mark);
        if (!ok) return false;
    }
    double td[3] = {t[0], t[1], t[2]}, sd[3] = {sc[0], sc[1], sc[2]};
    // Confined to the scene's folder tree like a glTF's URIs (docs/security.md).
    if (!st_path_confined(s->dir, rel, c->flags & ST_ASSETS_ANYWHERE, full, sizeof full, c->err)) {
        st_err_prefix(c->err, "%s: %s.vdb: ", c->file, c->path);
        return false;
    }
    st_density_grid *g = calloc(1, sizeof *g);
    if (!g) return st_fail(c->err, ST_ERR_RUNTIME, "%s: out of memory", c->file);
    if (!st_vdb_load(full, grid, td, sd, g, c->err)) {
        free(g);
        st_err_prefix(c->err, "%s: %s.vdb: ", c->file, c->path);
        return false;
    }
    s->density.kind = ST_DENSITY_GRID;
    s->density.grid = g;
    return st_scene_note_file(s, full, c->err);
}

static bool parse_density(st_jctx *c, const cJSON *v, st_scene *s) {
    st_density_desc *d = &s->density;
    static const char *const keys[] = {"height", "vdb", "grid", "transform", NULL};
    if (!st_j_object(c, v, keys)) return false;
    const cJSON *h = st_j_get(v, "height");
    if (h && st_j_get(v, "vdb"))
        return st_j_fail(c, NULL, "expected either \"height\" or \"vdb\", not both");
    if (h) {
        if (v->child->next) return st_j_fail(c, NULL, "\"height\" takes no other keys");
        size_t mark = st_j_push(c, "height");
        bool ok = parse_height_fog(c, h, d);
        st_j_pop(c, mark);
        return ok;
    }
    if (!st_j_get(v, "vdb")) return st_j_fail(c, NULL, "expected a \"height\" or a \"vdb\" key");
    return parse_vdb(c, v, s);
}

static bool parse_medium(st_jctx *c, const cJSON *v, st_scene *s) {
    static const char *const keys[] = {"sigma_s", "sigma_a", "phase", "density", NULL};
    st_medium_desc *m = &s->medium;
    bool has;
    if (!st_j_object(c, v, keys) || !st_j_vec3(c, v, "sigma_s", m->sigma_s, NULL) ||
        !st_j_range3(c, "sigma_s", m->sigma_s, 0, INFINITY) ||
        !st_j_vec3(c, v, "sigma_a", m->sigma_a, &has) ||
        !st_j_range3(c, "sigma_a", m->sigma_a, 0, INFINITY))
        return false;
    const cJSON *phase = st_j_get(v, "phase");
    if (phase) {
        size_t mark = st_j_push(c, "phase");
        bool ok = parse_phase(c, phase, m);
        st_j_pop(c, mark);
        if (!ok) return false;
    }
    const cJSON *density = st_j_get(v, "density");
    if (density) {
        size_t mark = st_j_push(c, "density");
        bool ok = parse_density(c, density, s);
        st_j_pop(c, mark);
        if (!ok) return false;
    }
    m->present = true;
    return true;
}

static bool parse_param(st_jctx *c, const cJSON *p, st_module_setting *m) {
    st_value val = {0};
    if (!st_j_identifier(p->string, ST_NAME_MAX))
        return st_j_fail(c, NULL, "parameter names are identifiers of 1..%d characters",
                         ST_NAME_MAX - 1);
    if (cJSON_IsNumber(p)) {
        if (!isfinite(p->valuedouble)) return st_j_fail(c, NULL, "number is not finite");
        val.type = ST_VALUE_NUMBER;
        val.number = p->valuedouble;
    } else if (cJSON_IsBool(p)) {
        val.type = ST_VALUE_BOOL;
        val.number = cJSON_IsTrue(p);
    } else if (cJSON_IsString(p)) {
        size_t n = strlen(p->valuestring);
        if (n >= ST_NAME_MAX)
            return st_j_fail(c, NULL, "string longer than %d characters", ST_NAME_MAX - 1);
        val.type = ST_VALUE_STRING;
        memcpy(val.str, p->valuestring, n + 1);
    } else {
        return st_j_fail(c, NULL, "expected a number, true/false or a string");
    }
    if (!st_module_setting_put(m, p->string, &val, c->err)) {
        st_err_prefix(c->err, "%s: %s: ", c->file, c->path);
        return false;
    }
    return true;
}

static bool parse_module(st_jctx *c, const cJSON *v, st_scene *s) {
    static const char *const keys[] = {"name", "params", NULL};
    char name[ST_NAME_MAX];
    if (!st_j_object(c, v, keys) || !st_j_string(c, v, "name", name, sizeof name, NULL))
        return false;
    if (!st_j_identifier(name, ST_NAME_MAX))
        return st_j_fail(c, "name", "'%s' is not an identifier ([A-Za-z_][A-Za-z0-9_]*)", name);
    for (int i = 0; i < s->num_modules; i++)
        if (!strcmp(s->modules[i].name, name))
            return st_j_fail(c, "name", "module '%s' is listed twice (also modules[%d])", name, i);
    st_module_setting *arr = realloc(s->modules, (size_t)(s->num_modules + 1) * sizeof *arr);
    if (!arr) return st_fail(c->err, ST_ERR_RUNTIME, "%s: %s: out of memory", c->file, c->path);
    s->modules = arr;
    st_module_setting *m = &arr[s->num_modules++];
    memset(m, 0, sizeof *m);
    memcpy(m->name, name, sizeof name);

    const cJSON *params = st_j_get(v, "params");
    if (!params) return true;
    size_t mark = st_j_push(c, "params");
    bool ok = st_j_object(c, params, NULL);
    for (const cJSON *p = ok ? params->child : NULL; p && ok; p = p->next) {
        size_t pm = st_j_push(c, p->string);
        ok = parse_param(c, p, m);
        st_j_pop(c, pm);
    }
    st_j_pop(c, mark);
    return ok;
}

static bool parse_modules(st_jctx *c, const cJSON *v, st_scene *s) {
    if (!cJSON_IsArray(v)) return st_j_fail(c, NULL, "expected an array");
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        size_t mark = st_j_push_index(c, i);
        bool ok = parse_module(c, e, s);
        st_j_pop(c, mark);
        if (!ok) return false;
    }
    return true;
}

// JSON keys override a glTF camera key by key; without one, position,
// target and fov_y are required and up/near/far have defaults.
static bool parse_camera(st_jctx *c, const cJSON *v, bool from_gltf, st_camera_desc *cam) {
    static const char *const keys[] = {"position", "target", "up", "fov_y", "near", "far", NULL};
    if (!v && !from_gltf)
        return st_j_fail(c, NULL,
                         "required (no glTF file supplies a camera; --auto-camera frames the "
                         "geometry)");
    if (!from_gltf) *cam = (st_camera_desc){.up = {0, 1, 0}, .near_z = 0.05f, .far_z = 100.0f};
    bool has, *req = from_gltf ? &has : NULL;
    if (v &&
        (!st_j_object(c, v, keys) || !st_j_vec3(c, v, "position", cam->position, req) ||
         !st_j_vec3(c, v, "target", cam->target, req) || !st_j_vec3(c, v, "up", cam->up, &has) ||
         !st_j_float(c, v, "fov_y", &cam->fov_y, req) ||
         !st_j_float(c, v, "near", &cam->near_z, &has) ||
         !st_j_float(c, v, "far", &cam->far_z, &has)))
        return false;
    if (!(cam->fov_y > 0 && cam->fov_y < 180))
        return st_j_fail(c, "fov_y", "%.9g is out of range (0, 180) degrees", cam->fov_y);
    if (!(cam->near_z > 0)) return st_j_fail(c, "near", "expected > 0, got %g", cam->near_z);
    if (!(cam->far_z > cam->near_z))
        return st_j_fail(c, "far", "%g is not greater than near (%g)", cam->far_z, cam->near_z);
    double d[3], u[3], dd = 0, uu = 0, du = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = (double)cam->target[k] - cam->position[k];
        u[k] = cam->up[k];
        dd += d[k] * d[k], uu += u[k] * u[k], du += d[k] * u[k];
    }
    if (dd == 0) return st_j_fail(c, "target", "equals position (no view direction)");
    if (uu == 0) return st_j_fail(c, "up", "zero vector");
    // sin^2 of the angle between up and the view direction.
    if (1.0 - du * du / (dd * uu) < 1e-10)
        return st_j_fail(c, "up", "parallel to the view direction");
    return true;
}

// Runs fn on root[key] with the path set to key; absent keys are skipped.
#define SECTION(key, call)                                                                         \
    do {                                                                                           \
        const cJSON *v = st_j_get(root, key);                                                      \
        if (v) {                                                                                   \
            size_t mark_ = st_j_push(c, key);                                                      \
            bool ok_ = (call);                                                                     \
            st_j_pop(c, mark_);                                                                    \
            if (!ok_) return false;                                                                \
        }                                                                                          \
    } while (0)

static bool parse_document(st_jctx *c, const cJSON *root, st_scene *s) {
    static const char *const keys[] = {"image",  "camera",  "lights",     "geometry",
                                       "medium", "modules", "background", "inscatter_overlay",
                                       NULL};
    if (!cJSON_IsObject(root)) return st_j_fail(c, NULL, "expected a JSON object at the top level");
    if (!st_j_object(c, root, keys)) return false;
    s->width = s->height = 512;
    s->filter = ST_FILTER_BOX; // what Cycles, Mitsuba and pbrt report
    SECTION("image", parse_image(c, v, s));
    SECTION("medium", parse_medium(c, v, s));
    // Radiance where camera rays leave the scene, >= 0 per channel.
    if (!st_j_vec3(c, root, "background", s->background, &s->has_background) ||
        !st_j_range3(c, "background", s->background, 0, INFINITY))
        return false;
    SECTION("modules", parse_modules(c, v, s));
    SECTION("lights", parse_lights(c, v, s));
    int json_lights = s->num_lights;
    bool gltf_camera = false;
    SECTION("geometry", st_scene_parse_geometry(c, v, s, &gltf_camera));
    // A "lights" key replaces the lights glTF files brought.
    if (st_j_get(root, "lights")) s->num_lights = json_lights;

    bool over = false;
    if (!st_j_bool(c, root, "inscatter_overlay", &s->inscatter_overlay, &over)) return false;
    const cJSON *cam = st_j_get(root, "camera");
    double lo[3], hi[3];
    if (!cam && !gltf_camera && (c->flags & ST_AUTO_CAMERA)) {
        if (!st_scene_bounds(s, lo, hi))
            return st_j_fail(c, "camera", "required: there is no geometry to frame");
        s->camera = st_scene_auto_camera(lo, hi);
        s->camera_auto = true;
        return true;
    }
    size_t mark = st_j_push(c, "camera");
    bool ok = parse_camera(c, cam, gltf_camera, &s->camera);
    st_j_pop(c, mark);
    return ok;
}

// Line and column (1-based) of offset `at` in text, for syntax errors.
static void line_col(const char *text, size_t at, int *line, int *col) {
    *line = 1, *col = 1;
    for (size_t i = 0; i < at; i++) {
        if (text[i] == '\n')
            ++*line, *col = 1;
        else
            ++*col;
    }
}

// Scene files are shallow; deeper nesting is refused with its own message
// (cJSON would only say "invalid JSON" past its limit of 1000).
#define ST_SCENE_MAX_DEPTH 64
#define ST_STR2(x) #x
#define ST_STR(x) ST_STR2(x)

// What cJSON cannot report: a NUL byte, raw or escaped as \u0000 (cJSON
// cuts the string there, so "shadow_map\u0000x" would read as shadow_map),
// and the nesting depth. Returns the offending offset and a message, or NULL.
static const char *prescan(const char *json, size_t len, size_t *at) {
    int depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < len; i++) {
        char ch = json[i];
        *at = i;
        if (!ch) return "NUL byte (not a text file)";
        if (in_string) {
            if (ch == '"') {
                in_string = false;
            } else if (ch == '\\' && i + 1 < len) {
                if (json[i + 1] == 'u' && i + 5 < len && !memcmp(json + i + 2, "0000", 4))
                    return "\\u0000 (NUL) in a string";
                i++;
            }
        } else if (ch == '"') {
            in_string = true;
        } else if (ch == '[' || ch == '{') {
            if (++depth > ST_SCENE_MAX_DEPTH)
                return "nested deeper than " ST_STR(ST_SCENE_MAX_DEPTH) " levels (the limit)";
        } else if (ch == ']' || ch == '}') {
            depth--;
        }
    }
    return NULL;
}

bool st_scene_parse(const char *json, size_t len, const char *path, st_scene *out, st_err *err) {
    return st_scene_parse_ex(json, len, path, NULL, out, err);
}

bool st_scene_parse_ex(const char *json, size_t len, const char *path, const st_scene_opts *opts,
                       st_scene *out, st_err *err) {
    memset(out, 0, sizeof *out);
    if (!path || !path[0]) path = "<scene>";
    if (strlen(path) >= sizeof out->path)
        return st_fail(err, ST_ERR_INPUT, "%.64s...: path longer than %zu characters", path,
                       sizeof out->path - 1);
    if (!json) return st_fail(err, ST_ERR_INPUT, "%s: no data", path);
    snprintf(out->path, sizeof out->path, "%s", path);
    st_path_dir(out->dir, sizeof out->dir, path);

    size_t bad_at = 0;
    const char *bad = prescan(json, len, &bad_at);
    if (bad) {
        int line, col;
        line_col(json, bad_at, &line, &col);
        memset(out, 0, sizeof *out);
        return st_fail(err, ST_ERR_INPUT, "%s: line %d, column %d: %s", path, line, col, bad);
    }
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(json, len, &end, false);
    size_t at = end && end >= json && end <= json + len ? (size_t)(end - json) : 0;
    if (root) // only whitespace may follow the value
        while (at < len &&
               (json[at] == ' ' || json[at] == '\t' || json[at] == '\n' || json[at] == '\r'))
            at++;
    if (!root || at < len) {
        int line, col;
        line_col(json, at, &line, &col);
        const char *what = root ? "unexpected text after the JSON value" : "invalid JSON";
        cJSON_Delete(root);
        memset(out, 0, sizeof *out);
        return st_fail(err, ST_ERR_INPUT, "%s: line %d, column %d: %s", path, line, col, what);
    }
    st_jctx c = {.file = path, .err = err, .flags = opts ? opts->flags : 0};
    bool ok = parse_document(&c, root, out);
    cJSON_Delete(root);
    if (!ok) st_scene_free(out);
    return ok;
}

bool st_scene_load(const char *path, st_scene *out, st_err *err) {
    return st_scene_load_ex(path, NULL, out, err);
}

bool st_scene_load_ex(const char *path, const st_scene_opts *opts, st_scene *out, st_err *err) {
    memset(out, 0, sizeof *out);
    if (!path) return st_fail(err, ST_ERR_INPUT, "no scene file given");
    size_t len = 0;
    char *text = st_read_input(path, ST_CAP_SCENE, "scene file", &len, err);
    if (!text) return false;
    bool ok = st_scene_parse_ex(text, len, path, opts, out, err);
    free(text);
    if (ok && !st_scene_note_file(out, path, err)) {
        st_scene_free(out);
        return false;
    }
    return ok;
}
