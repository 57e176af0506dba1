// Plugin loading: find by name, dlopen, ABI checks, parameter helpers.
#define _GNU_SOURCE
#include "st_list.h"
#include "st_module.h"
#include <dirent.h>
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

struct st_plugin_lib {
    void *handle;
    st_plugin desc; // zero-extended copy
    char path[1024];
    st_pass_decl *passes; // an older minor's pass table, rows zero-extended (desc.passes)
};

// An installed strahl (st_install_prefix non-empty) searches its own prefix
// but never the build tree it was built in: a plugin missing from the prefix
// and from $STRAHL_MODULE_PATH must not be picked up from a stale build.
void st_plugin_dirs(char *out, size_t n) {
    const char *env = getenv("STRAHL_MODULE_PATH");
    const char *pre = st_install_prefix();
    snprintf(out, n, "%s%s%s%s%s", env ? env : "", env && env[0] ? ":" : "", pre,
             pre[0] ? "/lib/strahl/modules:" : ST_MODULE_BUILD_DIR ":", ST_MODULE_INSTALL_DIR);
}

// The plugin's own shader folder, <dir of the .so>/shaders/<name>/ (the
// layout of the source tree's shaders/), when it has one.
static void register_shaders(const char *path, const char *name) {
    char dir[1024], sh[1300];
    struct stat st;
    st_path_dir(dir, sizeof dir, path);
    snprintf(sh, sizeof sh, "%s/shaders/%s", dir, name);
    if (stat(sh, &st) == 0 && S_ISDIR(st.st_mode)) st_shader_add_dir(name, sh);
}

// The sizes the plugin was built with (ST_PLUGIN exports them) against ours.
// Structs the plugin embeds, fills or indexes as arrays must match exactly;
// those the world allocates and the plugin only reads through a pointer may
// have grown at the end since.
// *pass_decl: the plugin's sizeof(st_pass_decl); where it does not say, the
// size its minor version had (a 1.3 row ends before `program`).
static bool check_sizes(void *h, const char *nm, const char *path, unsigned minor,
                        size_t *pass_decl, st_err *err) {
    st_abi_sizes_fn fn;
    *(void **)&fn = dlsym(h, ST_PLUGIN_SIZES_SYMBOL);
    *pass_decl = minor < 4 ? offsetof(st_pass_decl, program) : sizeof(st_pass_decl);
    if (!fn) return true; // a hand-written descriptor: abi_major/minor only
    const st_abi_sizes *theirs = fn();
    static const st_abi_sizes ours = ST_ABI_SIZES;
    if (!theirs || theirs->struct_size < sizeof(uint32_t) * 2)
        return st_fail(err, ST_ERR_INPUT, "module '%s' (%s): bad '%s' table", nm, path,
                       ST_PLUGIN_SIZES_SYMBOL);
    static const struct {
        const char *name;
        size_t offset;
        bool grows; // may be smaller in the plugin
    } fields[] = {
#define F(f, g) {"st_" #f, offsetof(st_abi_sizes, f), g}
        F(plugin, true),       F(param_def, false), F(pass_info, false),    F(uniform, false),
        F(frame, true),        F(scene, true),      F(light_desc, false),   F(mesh, false),
        F(shader, true),       F(target, false),    F(buffer, false),       F(err, false),
        F(target_desc, false), F(pass_decl, true),  F(program_decl, false), F(export_decl, false),
#undef F
    };
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        if (fields[i].offset + sizeof(uint32_t) > theirs->struct_size) continue; // not known then
        uint32_t a, b;
        memcpy(&a, (const char *)theirs + fields[i].offset, sizeof a);
        memcpy(&b, (const char *)&ours + fields[i].offset, sizeof b);
        if (fields[i].offset == offsetof(st_abi_sizes, pass_decl)) *pass_decl = a;
        if (a == b || (fields[i].grows && a < b)) continue;
        return st_fail(
            err, ST_ERR_INPUT,
            "module '%s' (%s): built with a different %s (%u bytes, this strahl has %u): "
            "rebuild it against this strahl's headers",
            nm, path, fields[i].name, a, b);
    }
    return true;
}

// Declared passes (ABI 1.3): a count of rows that matches the table, each
// row one pass or one per light.
static bool valid_pass_table(const st_plugin *d) {
    if (d->num_pass_decls < 0 || (d->num_pass_decls > 0 && !d->passes)) return false;
    for (int i = 0; i < d->num_pass_decls; i++)
        if (d->passes[i].count < ST_PER_LIGHT || d->passes[i].count > 1) return false;
    return true;
}

static int find_program(const st_plugin *d, const char *name) {
    for (int i = 0; name && i < d->num_programs; i++)
        if (d->programs[i].name && !strcmp(d->programs[i].name, name)) return i;
    return -1;
}

// Programs and exports (ABI 1.4): every program named and either graphics or
// compute, every pass's program in the table, every export one parameter of
// the module or one target. "" when valid, else what is wrong.
static const char *bad_programs(const st_plugin *d) {
    if (d->num_programs < 0 || d->num_programs > ST_MAX_PROGRAMS ||
        (d->num_programs > 0 && !d->programs))
        return "program table";
    if (d->num_exports < 0 || (d->num_exports > 0 && !d->exports)) return "export table";
    for (int i = 0; i < d->num_programs; i++) {
        const st_program_decl *q = &d->programs[i];
        if (!q->name || !q->frag == !q->comp || find_program(d, q->name) != i)
            return "program table (each: a unique name, and frag or comp)";
        char tok[ST_NAME_MAX];
        for (const char *s = q->param_defines; (s = st_list_next(s, tok, NULL));)
            if (tok[0] && st_param_index(d, tok) < 0) return "program parameter define";
    }
    for (int i = 0; i < d->num_pass_decls; i++)
        if (d->passes[i].program && find_program(d, d->passes[i].program) < 0)
            return "pass program (not in the program table)";
    for (int i = 0; i < d->num_exports; i++) {
        const st_export_decl *e = &d->exports[i];
        if (!e->uniform || !e->param == !e->target || (e->param && st_param_index(d, e->param) < 0))
            return "export (each: a uniform, and one parameter or target)";
    }
    return "";
}

static bool valid_name(const char *name) {
    if (!name[0] || strlen(name) >= ST_NAME_MAX) return false;
    for (const char *p = name; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_')) return false;
    return true;
}

st_plugin_lib *st_plugin_open(const char *name, st_err *err) {
    // A scene names a module, never a path.
    if (!valid_name(name)) {
        st_fail(err, ST_ERR_INPUT,
                "module '%s': not a module name (lowercase letters, digits, '_')", name);
        return NULL;
    }
    char dirs[4096];
    st_plugin_dirs(dirs, sizeof dirs);
    for (char *save = NULL, *d = strtok_r(dirs, ":", &save); d; d = strtok_r(NULL, ":", &save)) {
        char path[1200];
        struct stat st;
        snprintf(path, sizeof path, "%s/%s.so", d, name);
        if (stat(path, &st) == 0) {
            st_plugin_lib *lib = st_plugin_open_file(path, err);
            if (lib && strcmp(lib->desc.name, name)) {
                st_fail(err, ST_ERR_INPUT, "%s: declares name '%s', expected '%s'", path,
                        lib->desc.name, name);
                st_plugin_close(lib);
                return NULL;
            }
            return lib;
        }
    }
    st_plugin_dirs(dirs, sizeof dirs);
    st_fail(err, ST_ERR_INPUT, "unknown module '%s' (searched %s)", name, dirs);
    return NULL;
}

// The descriptor as copied: every required hook (naming all that are
// missing at once; a table of declared passes stands in for num_passes and
// pass_info, and for create and destroy), the parameter and pass tables.
static bool check_desc(const st_plugin *d, const char *nm, const char *path, st_err *err) {
    char missing[256] = "";
    bool declared = d->passes && d->num_pass_decls > 0;
    const struct {
        const void *p;
        const char *name;
    } req[] = {{d->name, "name"},
               {declared ? (const void *)"" : (const void *)d->create, "create"},
               {declared && !d->create ? (const void *)"" : (const void *)d->destroy, "destroy"},
               {declared ? (const void *)"" : (const void *)d->num_passes, "num_passes"},
               {declared ? (const void *)"" : (const void *)d->pass_info, "pass_info"}};
    for (size_t i = 0; i < sizeof req / sizeof req[0]; i++) {
        if (req[i].p) continue;
        size_t l = strlen(missing);
        snprintf(missing + l, sizeof missing - l, "%s%s", l ? ", " : "", req[i].name);
    }
    if (missing[0])
        return st_fail(err, ST_ERR_INPUT, "module '%s' (%s): missing required hook(s): %s", nm,
                       path, missing);
    if (d->num_params < 0 || d->num_params > ST_MAX_PARAMS || (d->num_params > 0 && !d->params))
        return st_fail(err, ST_ERR_INPUT, "module '%s' (%s): bad parameter table", nm, path);
    if (!valid_pass_table(d))
        return st_fail(err, ST_ERR_INPUT, "module '%s' (%s): bad pass table (ST_PASSES)", nm, path);
    const char *bad = bad_programs(d);
    if (bad[0]) return st_fail(err, ST_ERR_INPUT, "module '%s' (%s): bad %s", nm, path, bad);
    return true;
}

st_plugin_lib *st_plugin_open_file(const char *path, st_err *err) {
    dlerror();
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *e = dlerror();
        st_fail(err, ST_ERR_INPUT, "%s: cannot load: %s", path, e ? e : "unknown error");
        return NULL;
    }
    st_plugin_fn fn;
    *(void **)&fn = dlsym(h, ST_PLUGIN_SYMBOL);
    if (!fn) {
        st_fail(err, ST_ERR_INPUT, "%s: no '%s' symbol: not a strahl module", path,
                ST_PLUGIN_SYMBOL);
        dlclose(h);
        return NULL;
    }
    const st_plugin *d = fn();
    if (!d) {
        st_fail(err, ST_ERR_INPUT, "%s: '%s' returned no descriptor", path, ST_PLUGIN_SYMBOL);
        dlclose(h);
        return NULL;
    }
    const char *nm = d->struct_size >= offsetof(st_plugin, description) && d->name ? d->name : "?";
    if (d->abi_major != ST_ABI_MAJOR || d->abi_minor > ST_ABI_MINOR) {
        st_fail(err, ST_ERR_INPUT,
                "module '%s' (%s): built for plugin ABI %u.%u, this strahl supports %d.0..%d.%d",
                nm, path, d->abi_major, d->abi_minor, ST_ABI_MAJOR, ST_ABI_MAJOR, ST_ABI_MINOR);
        dlclose(h);
        return NULL;
    }
    size_t row_size = sizeof(st_pass_decl);
    if (!check_sizes(h, nm, path, d->abi_minor, &row_size, err)) {
        dlclose(h);
        return NULL;
    }
    st_plugin_lib *lib = calloc(1, sizeof *lib);
    if (!lib) {
        dlclose(h);
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    size_t n = d->struct_size < sizeof lib->desc ? d->struct_size : sizeof lib->desc;
    memcpy(&lib->desc, d, n);
    lib->handle = h;
    // A pass table of an older minor has shorter rows: copied into ours,
    // the fields it does not know zero (ABI 1.4 appended `program`).
    if (row_size < sizeof(st_pass_decl) && lib->desc.passes && lib->desc.num_pass_decls > 0) {
        int rows = lib->desc.num_pass_decls;
        if (rows <= 4096) lib->passes = calloc((size_t)rows, sizeof *lib->passes);
        if (!lib->passes) { // more rows than any plugin has: refused, never misread
            dlclose(h);
            free(lib);
            if (rows > 4096)
                st_fail(err, ST_ERR_INPUT, "module '%s' (%s): bad pass table (%d rows)", nm, path,
                        rows);
            else
                st_fail(err, ST_ERR_RUNTIME, "out of memory");
            return NULL;
        }
        for (int i = 0; i < lib->desc.num_pass_decls; i++)
            memcpy(&lib->passes[i], (const char *)lib->desc.passes + (size_t)i * row_size,
                   row_size);
        lib->desc.passes = lib->passes;
    }
    snprintf(lib->path, sizeof lib->path, "%s", path);
    if (!check_desc(&lib->desc, nm, path, err)) {
        dlclose(h);
        free(lib->passes);
        free(lib);
        return NULL;
    }
    register_shaders(path, lib->desc.name);
    return lib;
}

const st_plugin *st_plugin_desc(const st_plugin_lib *lib) {
    return &lib->desc;
}

void st_plugin_close(st_plugin_lib *lib) {
    if (!lib) return;
    if (lib->desc.cleanup) lib->desc.cleanup();
    dlclose(lib->handle);
    free(lib->passes);
    free(lib);
}

static int cmp_names(const void *a, const void *b) {
    return strcmp(a, b);
}

int st_plugin_list(char names[][ST_NAME_MAX], int max) {
    char dirs[4096];
    int n = 0;
    st_plugin_dirs(dirs, sizeof dirs);
    for (char *save = NULL, *d = strtok_r(dirs, ":", &save); d; d = strtok_r(NULL, ":", &save)) {
        DIR *dir = opendir(d);
        if (!dir) continue;
        for (struct dirent *e; (e = readdir(dir));) {
            size_t l = strlen(e->d_name);
            if (l < 4 || l - 3 >= ST_NAME_MAX || strcmp(e->d_name + l - 3, ".so")) continue;
            char nm[ST_NAME_MAX];
            snprintf(nm, sizeof nm, "%.*s", (int)(l - 3), e->d_name);
            if (!valid_name(nm)) continue;
            bool dup = false;
            for (int i = 0; i < n; i++)
                dup |= !strcmp(names[i], nm);
            if (!dup && n < max) snprintf(names[n++], ST_NAME_MAX, "%s", nm);
        }
        closedir(dir);
    }
    qsort(names, (size_t)n, ST_NAME_MAX, cmp_names);
    return n;
}

int st_param_index(const st_plugin *p, const char *name) {
    for (int i = 0; i < p->num_params; i++)
        if (!strcmp(p->params[i].name, name)) return i;
    return -1;
}

// The k-th name of "a|b|c" and its length; NULL past the end. The one place
// that reads the choice syntax.
static const char *choice_at(const char *choices, int k, size_t *len) {
    const char *c = choices;
    for (int i = 0; c && *c; i++) {
        const char *bar = strchr(c, '|');
        if (i == k) {
            *len = bar ? (size_t)(bar - c) : strlen(c);
            return c;
        }
        c = bar ? bar + 1 : NULL;
    }
    return NULL;
}

int st_param_num_choices(const st_param_def *d) {
    size_t l;
    int n = 0;
    while (choice_at(d->choices, n, &l))
        n++;
    return n;
}

bool st_param_choice(const st_param_def *d, int k, char *out, size_t n) {
    size_t l = 0;
    const char *c = choice_at(d->choices, k, &l);
    snprintf(out, n, "%.*s", (int)l, c ? c : "");
    return c != NULL;
}

static int choice_index(const char *choices, const char *s) {
    size_t l, sl = strlen(s);
    const char *c;
    for (int i = 0; (c = choice_at(choices, i, &l)); i++)
        if (l == sl && !strncmp(c, s, l)) return i;
    return -1;
}

bool st_param_from_value(const st_plugin *p, int index, const st_value *v, double *out,
                         st_err *err) {
    const st_param_def *d = &p->params[index];
    switch (d->type) {
    case ST_PARAM_BOOL:
        if (v->type == ST_VALUE_BOOL ||
            (v->type == ST_VALUE_NUMBER && (v->number == 0 || v->number == 1))) {
            *out = v->number != 0;
            return true;
        }
        return st_fail(err, ST_ERR_INPUT, "%s.%s: expected true or false", p->name, d->name);
    case ST_PARAM_ENUM: {
        if (v->type != ST_VALUE_STRING)
            return st_fail(err, ST_ERR_INPUT, "%s.%s: expected one of %s", p->name, d->name,
                           d->choices);
        int k = choice_index(d->choices, v->str);
        if (k < 0)
            return st_fail(err, ST_ERR_INPUT, "%s.%s: '%s' is not one of %s", p->name, d->name,
                           v->str, d->choices);
        *out = k;
        return true;
    }
    case ST_PARAM_INT:
    case ST_PARAM_FLOAT:
        if (v->type != ST_VALUE_NUMBER || !isfinite(v->number))
            return st_fail(err, ST_ERR_INPUT, "%s.%s: expected a number", p->name, d->name);
        if (d->type == ST_PARAM_INT && v->number != floor(v->number))
            return st_fail(err, ST_ERR_INPUT, "%s.%s: %.9g is not an integer", p->name, d->name,
                           v->number);
        if (v->number < d->min || v->number > d->max)
            return st_fail(err, ST_ERR_INPUT, "%s.%s: %.9g is out of range [%g, %g]", p->name,
                           d->name, v->number, d->min, d->max);
        *out = v->number;
        return true;
    }
    return st_fail(err, ST_ERR_INPUT, "%s.%s: bad parameter type", p->name, d->name);
}

void st_param_format(const st_param_def *d, double v, char *out, size_t n) {
    if (d->type == ST_PARAM_BOOL) {
        snprintf(out, n, "%s", v != 0 ? "true" : "false");
    } else if (d->type == ST_PARAM_ENUM) {
        if (!st_param_choice(d, (int)v, out, n)) snprintf(out, n, "%d", (int)v);
    } else {
        snprintf(out, n, "%g", v);
    }
}
