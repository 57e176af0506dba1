// Parameter stress, driven by the installed plugins' own tables
// (`strahl modules --json`), so a plugin added later is covered unchanged.
//
//   test_stress_params            every table is consistent (defaults inside
//                                 their ranges, enums with choices, names unique)
//   test_stress_params MODULE     a small scene renders with each parameter of
//                                 MODULE at its minimum and maximum (every
//                                 choice of an enum, both bools), each with every
//                                 value finite and non-negative, or is refused
//                                 with exit 2 naming the parameter; a value just
//                                 outside the range (a non-0/1 bool, an unknown
//                                 choice) is refused with exit 2, one line naming
//                                 MODULE.PARAM and no output file, both in the
//                                 scene file and through --set.
#include "stress.h"
#include <cjson/cJSON.h>

enum { N = 32 };

// Cheap settings for the other parameters while one is at a limit (only
// those a plugin has are used).
typedef struct base_param {
    const char *module, *param;
    double value;
} base_param;
static const base_param BASE[] = {
    {"shadow_map", "resolution", 128}, {"toth", "samples", 16}, {"atlas_gi", "atlas_size", 64},
    {"atlas_gi", "samples", 16},       {"ssgi", "samples", 16}, {"mitchell", "n", 32},
};

// Values that switch an effect off: the image must equal the one without
// the module (value as the test writes it: "%.17g" of a limit, or a choice).
typedef struct neutral {
    const char *module, *param, *value;
} neutral;
static const neutral NEUTRAL[] = {
    {"mitchell", "exposure", "0"}, {"sousa", "brightness", "0"}, {"atlas_gi", "display", "direct"}};

static int is_neutral(const char *module, const char *param, const char *value) {
    for (size_t k = 0; k < sizeof NEUTRAL / sizeof NEUTRAL[0]; k++)
        if (!strcmp(NEUTRAL[k].module, module) && !strcmp(NEUTRAL[k].param, param) &&
            !strcmp(NEUTRAL[k].value, value))
            return 1;
    return 0;
}

static cJSON *modules_json(void) {
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "%s modules --json 2>/dev/null", ST_TEST_STRAHL);
    FILE *p = popen(cmd, "r");
    if (!p) return NULL;
    static char buf[1 << 18];
    size_t n = fread(buf, 1, sizeof buf - 1, p);
    buf[n] = 0;
    int rc = pclose(p);
    CHECK(rc == 0, "strahl modules --json: exit status %d", rc);
    return cJSON_Parse(buf);
}

static const char *str(const cJSON *o, const char *key) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsString(v) ? v->valuestring : "";
}
static double num(const cJSON *o, const char *key) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

// Whether a comma-separated list contains `name` (a trailing '?' ignored).
static int list_has(const char *list, const char *name) {
    size_t n = strlen(name);
    for (const char *p = list; p && *p;) {
        while (*p == ' ' || *p == ',')
            p++;
        const char *e = p;
        while (*e && *e != ',')
            e++;
        size_t l = (size_t)(e - p);
        if (l && p[l - 1] == '?') l--;
        if (l == n && !strncmp(p, name, n)) return 1;
        p = e;
    }
    return 0;
}

static int table_checks(const cJSON *mods) {
    int nm = 0;
    const cJSON *m;
    cJSON_ArrayForEach(m, mods) {
        const char *name = str(m, "name");
        const cJSON *params = cJSON_GetObjectItemCaseSensitive(m, "params"), *p;
        nm++;
        CHECK(name[0] != 0, "module without a name");
        int np = 0;
        cJSON_ArrayForEach(p, params) {
            const char *pn = str(p, "name"), *type = str(p, "type");
            const cJSON *q;
            int dup = 0, i = 0;
            cJSON_ArrayForEach(q, params) if (i++ < np) dup += !strcmp(str(q, "name"), pn);
            np++;
            CHECK(!dup, "%s.%s: listed twice", name, pn);
            CHECK(str(p, "help")[0] != 0, "%s.%s: no help text", name, pn);
            if (!strcmp(type, "float") || !strcmp(type, "int")) {
                double lo = num(p, "min"), hi = num(p, "max"), def = num(p, "default");
                CHECK(lo < hi, "%s.%s: range [%g, %g]", name, pn, lo, hi);
                CHECK(def >= lo && def <= hi, "%s.%s: default %g outside [%g, %g]", name, pn, def,
                      lo, hi);
                if (!strcmp(type, "int"))
                    CHECK(lo == floor(lo) && hi == floor(hi) && def == floor(def),
                          "%s.%s: int with fractions", name, pn);
            } else if (!strcmp(type, "enum")) {
                const char *choices = str(p, "choices"), *def = str(p, "default");
                CHECK(strchr(choices, '|') != NULL, "%s.%s: enum with one choice '%s'", name, pn,
                      choices);
                CHECK(list_has(choices, def) || strstr(choices, def),
                      "%s.%s: default '%s' not in %s", name, pn, def, choices);
            } else {
                CHECK(!strcmp(type, "bool"), "%s.%s: unknown type '%s'", name, pn, type);
            }
        }
    }
    printf("  %d modules\n", nm);
    CHECK(nm >= 1, "no module installed (STRAHL_MODULE_PATH?)");
    return nm;
}

// ---- one module ---------------------------------------------------------------

static const cJSON *all_mods;
static char json[16384];

// The providers of what `m` requires (optional ones too: that is how the
// plugin is used), then (if self) m with base settings, `param` set to
// `value` (a JSON value) unless param is NULL.
static void scene_modules(const cJSON *m, const char *param, const char *value, int self) {
    const char *name = str(m, "name"), *req = str(m, "requires");
    char mods[4096] = "";
    size_t n = 0;
    const cJSON *o;
    cJSON_ArrayForEach(o, all_mods) {
        const char *on = str(o, "name");
        if (!strcmp(on, name) || !req[0]) continue;
        int provides = 0;
        for (const char *p = str(o, "provides"); *p;) {
            while (*p == ' ' || *p == ',')
                p++;
            const char *e = p;
            while (*e && *e != ',')
                e++;
            char cap[64];
            snprintf(cap, sizeof cap, "%.*s", (int)(e - p), p);
            if (cap[0] && list_has(req, cap)) provides = 1;
            p = e;
        }
        if (!provides) continue;
        n += (size_t)snprintf(mods + n, sizeof mods - n, "{\"name\": \"%s\", \"params\": {", on);
        int first = 1;
        for (size_t b = 0; b < sizeof BASE / sizeof BASE[0]; b++)
            if (!strcmp(BASE[b].module, on))
                n += (size_t)snprintf(mods + n, sizeof mods - n, "%s\"%s\": %g", first ? "" : ", ",
                                      BASE[b].param, BASE[b].value),
                    first = 0;
        n += (size_t)snprintf(mods + n, sizeof mods - n, "}}, ");
    }
    if (!self) {
        n -= n >= 2 ? 2 : 0; // the trailing ", "
        mods[n] = 0;
    } else {
        n += (size_t)snprintf(mods + n, sizeof mods - n, "{\"name\": \"%s\", \"params\": {", name);
        int first = 1;
        const cJSON *params = cJSON_GetObjectItemCaseSensitive(m, "params"), *p;
        for (size_t b = 0; b < sizeof BASE / sizeof BASE[0]; b++) {
            if (strcmp(BASE[b].module, name) || (param && !strcmp(BASE[b].param, param))) continue;
            int has = 0;
            cJSON_ArrayForEach(p, params) has |= !strcmp(str(p, "name"), BASE[b].param);
            if (!has) continue;
            n += (size_t)snprintf(mods + n, sizeof mods - n, "%s\"%s\": %g", first ? "" : ", ",
                                  BASE[b].param, BASE[b].value);
            first = 0;
        }
        if (param)
            n += (size_t)snprintf(mods + n, sizeof mods - n, "%s\"%s\": %s", first ? "" : ", ",
                                  param, value);
        snprintf(mods + n, sizeof mods - n, "}}");
    }
    // A room with a pillar, a light in view and an emitting panel: shadows,
    // shafts, indirect light and a medium for every technique to work on.
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": %d, \"height\": %d},"
        " \"camera\": {\"position\": [0, 1.2, 1.8], \"target\": [0, 1.4, -1], \"up\": [0, 1, 0], "
        "\"fov_y\": 60},"
        " \"lights\": [{\"type\": \"point\", \"position\": [0.4, 1.7, -1.2], \"intensity\": [4, "
        "3.5, 3]}],"
        " \"geometry\": [{\"box\": {\"min\": [-2, 0, -2], \"max\": [2, 3, 2]}, \"inward\": true},"
        "  {\"box\": {\"min\": [-0.1, 0, -0.7], \"max\": [0.1, 2.5, -0.5]}, \"albedo\": [0.6, 0.3, "
        "0.2]},"
        "  {\"quad\": {\"corner\": [1.99, 0.5, -1], \"u\": [0, 0, 1], \"v\": [0, 1, 0]}, "
        "\"emission\": [0.5, 0.5, 0.5]}],"
        " \"medium\": {\"sigma_s\": [0.1, 0.12, 0.14], \"sigma_a\": [0.01, 0.01, 0.01], \"phase\": "
        "{\"hg\": 0.4}},"
        " \"modules\": [%s]}",
        N, N, mods);
}

static void scene_for(const cJSON *m, const char *param, const char *value) {
    scene_modules(m, param, value, 1);
}

static int renders, refusals_in_range, neutral_checked;

// Renders MODULE with `param` = `value`: a finite image, or a refusal that
// names the parameter.
static void limit(const char *module, const char *param, const char *value, const st_image *plain) {
    char name[160], out[512];
    snprintf(name, sizeof name, "%s_%s_%s", module, param, value);
    for (char *c = name; *c; c++)
        if (*c == '"' || *c == ' ' || *c == '/') *c = '_';
    stress_path(out, sizeof out, name, "exr");
    // In this process first (a process start-up per render cost more than
    // the render); a failure reruns `strahl render` for its exit code and message.
    char path[512];
    stress_path(path, sizeof path, name, "json");
    st_test_write(path, json);
    if (!stress_ctx) stress_ctx = st_test_context();
    st_image img = {0};
    st_err err = {0};
    int rc = 0;
    if (!st_test_render_frames_here(path, 2, &img, &err)) {
        st_image_free(&img);
        rc = stress_run("render", name, NULL, "--frames 2");
        CHECK(rc != 0, "%s: fails in process (%s), strahl render exits 0", name, err.msg);
    }
    renders++;
    if (rc == 2) {
        // A value inside the declared range that this scene cannot take.
        refusals_in_range++;
        printf("  %-44s refused: %s", name, stress_msg);
        CHECK(strstr(stress_msg, param) != NULL, "%s: the refusal names %s: %s", name, param,
              stress_msg);
        CHECK(stress_msg_lines() == 1, "%s: one message line, got %d", name, stress_msg_lines());
        CHECK(!st_test_exists(out), "%s: no output file", name);
        return;
    }
    CHECK(rc == 0, "%s: exit code %d: %s", name, rc, stress_msg);
    if (rc != 0) return;
    stress_stats s = stress_image_stats(&img);
    CHECK(s.nonfinite == 0, "%s: %zu non-finite values", name, s.nonfinite);
    CHECK(s.negative == 0, "%s: %zu negative values (min %g)", name, s.negative, s.min);
    CHECK(s.lit > 0, "%s: black image", name);
    double d = stress_rel_l1(&img, plain);
    printf("  %-44s mean %-10.4g max %-10.4g vs plain: L1 %.3g\n", name, s.mean, s.max, d);
    if (is_neutral(module, param, value)) {
        neutral_checked++;
        CHECK(d < 1e-5, "%s switches the effect off: relative L1 from the plain image %.3g", name,
              d);
    }
    st_image_free(&img);
}

static void refused(const char *module, const char *param, const char *value, int via_set,
                    const cJSON *m) {
    char name[160], set[256], qualified[160];
    snprintf(name, sizeof name, "%s_%s_bad_%d", module, param, via_set);
    snprintf(qualified, sizeof qualified, "%s.%s", module, param);
    if (via_set) {
        scene_for(m, NULL, NULL);
        snprintf(set, sizeof set, "--set '%s=%s'", qualified, value);
        stress_refused("render", name, json, set, qualified);
    } else {
        scene_for(m, param, value);
        stress_refused("render", name, json, NULL, qualified);
    }
}

static void module_limits(const cJSON *m) {
    const char *name = str(m, "name");
    // The plain image: the same scene with only the providers of what the
    // module requires, which a module that switches its effect off must
    // reproduce.
    st_image plain = {0};
    scene_modules(m, NULL, NULL, 0);
    char plain_name[96];
    snprintf(plain_name, sizeof plain_name, "%s_plain", name); // the modules' tests share a folder
    char plain_path[512];
    stress_path(plain_path, sizeof plain_path, plain_name, "json");
    st_test_write(plain_path, json);
    if (!stress_ctx) stress_ctx = st_test_context();
    st_err err = {0};
    CHECK(st_test_render_frames_here(plain_path, 2, &plain, &err), "%s: %s", plain_name, err.msg);
    CHECK(st_image_count_nonfinite(&plain) == 0, "%s: non-finite values", plain_name);

    const cJSON *params = cJSON_GetObjectItemCaseSensitive(m, "params"), *p;
    cJSON_ArrayForEach(p, params) {
        const char *pn = str(p, "name"), *type = str(p, "type");
        char lo[64], hi[64], below[64], above[64];
        if (!strcmp(type, "float") || !strcmp(type, "int")) {
            double a = num(p, "min"), b = num(p, "max");
            // Just outside: the next integer, or a millionth of the limit's
            // magnitude (at least 1e-6) for floats.
            double da = !strcmp(type, "int") ? 1 : 1e-6 * fmax(1, fabs(a));
            double db = !strcmp(type, "int") ? 1 : 1e-6 * fmax(1, fabs(b));
            snprintf(lo, sizeof lo, "%.17g", a);
            snprintf(hi, sizeof hi, "%.17g", b);
            snprintf(below, sizeof below, "%.17g", a - da);
            snprintf(above, sizeof above, "%.17g", b + db);
            scene_for(m, pn, lo);
            limit(name, pn, lo, &plain);
            scene_for(m, pn, hi);
            limit(name, pn, hi, &plain);
            refused(name, pn, below, 1, m);
            refused(name, pn, above, 0, m);
        } else if (!strcmp(type, "bool")) {
            scene_for(m, pn, "false");
            limit(name, pn, "false", &plain);
            scene_for(m, pn, "true");
            limit(name, pn, "true", &plain);
            refused(name, pn, "2", 0, m);
            refused(name, pn, "yes", 1, m);
        } else if (!strcmp(type, "enum")) {
            char choices[512], v[96];
            snprintf(choices, sizeof choices, "%s", str(p, "choices"));
            for (char *c = strtok(choices, "|"); c; c = strtok(NULL, "|")) {
                snprintf(v, sizeof v, "\"%s\"", c);
                scene_for(m, pn, v);
                limit(name, pn, c, &plain);
            }
            refused(name, pn, "\"no_such_choice\"", 0, m);
            refused(name, pn, "no_such_choice", 1, m);
            refused(name, pn, "1", 0, m); // a number for an enum
        }
    }
    st_image_free(&plain);
    // Every neutral value of this module's table was met.
    int want = 0;
    for (size_t k = 0; k < sizeof NEUTRAL / sizeof NEUTRAL[0]; k++) {
        if (strcmp(NEUTRAL[k].module, name)) continue;
        cJSON_ArrayForEach(p, params) want += !strcmp(str(p, "name"), NEUTRAL[k].param);
    }
    CHECK(neutral_checked == want, "%s: %d of %d neutral values checked", name, neutral_checked,
          want);
}

int main(int argc, char **argv) {
    double t0 = stress_now();
    cJSON *mods = modules_json();
    CHECK(cJSON_IsArray(mods), "strahl modules --json is a JSON array");
    if (!cJSON_IsArray(mods)) return st_test_summary("test_stress_params");
    all_mods = mods;
    if (argc < 2) {
        table_checks(mods);
    } else {
        const cJSON *m, *found = NULL;
        cJSON_ArrayForEach(m, mods) if (!strcmp(str(m, "name"), argv[1])) found = m;
        CHECK(found != NULL, "module '%s' is not installed", argv[1]);
        if (found) module_limits(found);
        printf("  %d renders at limits, %d refused in range, %d neutral, %.1f s\n", renders,
               refusals_in_range, neutral_checked, stress_now() - t0);
    }
    cJSON_Delete(mods);
    return st_test_summary(argc < 2 ? "test_stress_params" : argv[1]);
}
