// Switching techniques in a scene before its world exists (--enable and
// --disable on the command line, the Python binding): the module list is
// edited, and what an enabled module requires is added, from the installed
// plugins' descriptors, so that `--set` then reaches the enabled module.
#include "st_list.h"
#include "st_module.h"
#include "st_world.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Does plugin `module` provide capability cap? One that does not open
// provides nothing (the world names it when it loads the scene).
static bool plugin_provides(const char *module, const char *cap) {
    st_err ignore = {0};
    st_plugin_lib *lib = st_plugin_open(module, &ignore);
    if (!lib) return false;
    bool has = st_list_has(st_plugin_desc(lib)->provides, cap);
    st_plugin_close(lib);
    return has;
}

static bool scene_provides(const st_scene *s, const char *cap) {
    for (int i = 0; i < s->num_modules; i++)
        if (plugin_provides(s->modules[i].name, cap)) return true;
    return false;
}

static void module_names(const st_scene *s, char *out, size_t n) {
    out[0] = 0;
    for (int i = 0; i < s->num_modules; i++) {
        size_t l = strlen(out);
        snprintf(out + l, n - l, "%s%s", i ? ", " : "", s->modules[i].name);
    }
    if (!out[0]) snprintf(out, n, "none");
}

static bool disable_one(st_scene *s, const char *name, st_err *err) {
    st_module_setting *m = st_scene_module(s, name);
    if (!m) {
        char names[512];
        module_names(s, names, sizeof names);
        return st_fail(err, ST_ERR_INPUT,
                       "disable '%s': module '%s' is not in the scene (it has: %s)", name, name,
                       names);
    }
    free(m->params);
    int i = (int)(m - s->modules);
    memmove(m, m + 1, (size_t)(s->num_modules - i - 1) * sizeof *m);
    s->num_modules--;
    return true;
}

// After the disables: every module left still finds what it requires.
static bool check_requires(const st_scene *s, const char *disabled, st_err *err) {
    for (int i = 0; i < s->num_modules; i++) {
        st_err ignore = {0};
        st_plugin_lib *lib = st_plugin_open(s->modules[i].name, &ignore);
        if (!lib) continue;
        char cap[ST_NAME_MAX];
        bool optional, ok = true;
        for (const char *r = st_plugin_desc(lib)->requires;
             ok && (r = st_list_next(r, cap, &optional));)
            ok = !cap[0] || optional || scene_provides(s, cap);
        st_plugin_close(lib);
        if (!ok)
            return st_fail(err, ST_ERR_INPUT,
                           "disable '%s': module '%s' still requires '%s' (disable it too)",
                           disabled, s->modules[i].name, cap);
    }
    return true;
}

// Adds module `name` and, before it is done, what it requires that no module
// of the scene provides (a capability is the name of the plugin providing it,
// as st_world_enable assumes).
static bool enable_one(st_scene *s, const char *name, const char *asked, int depth, st_err *err) {
    if (st_scene_module(s, name)) return true;
    if (depth > 8)
        return st_fail(err, ST_ERR_INPUT, "enable '%s': requirements nest too deep", asked);
    if (strlen(name) >= ST_NAME_MAX)
        return st_fail(err, ST_ERR_INPUT, "enable '%s': name too long", asked);
    st_plugin_lib *lib = st_plugin_open(name, err);
    if (!lib) {
        st_err_prefix(err, "enable '%s': ", asked);
        return false;
    }
    char req[512];
    snprintf(req, sizeof req, "%s",
             st_plugin_desc(lib)->requires ? st_plugin_desc(lib)->requires : "");
    st_plugin_close(lib);
    st_module_setting *arr = realloc(s->modules, (size_t)(s->num_modules + 1) * sizeof *arr);
    if (!arr) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    s->modules = arr;
    arr[s->num_modules] = (st_module_setting){0};
    snprintf(arr[s->num_modules++].name, ST_NAME_MAX, "%s", name);
    char cap[ST_NAME_MAX];
    bool optional;
    for (const char *r = req; (r = st_list_next(r, cap, &optional));) {
        if (!cap[0] || optional || scene_provides(s, cap)) continue; // optional ones only order
        if (!enable_one(s, cap, asked, depth + 1, err)) return false;
    }
    return true;
}

bool st_scene_switch_modules(st_scene *s, const char *enable, const char *disable, st_err *err) {
    char name[ST_NAME_MAX];
    bool optional;
    for (int k = 0; k < 2; k++) // names only: "toth?" is requirement syntax
        for (const char *r = k ? enable : disable; r && (r = st_list_next(r, name, &optional));)
            if (optional)
                return st_fail(err, ST_ERR_INPUT, "%s '%s?': expected a module name",
                               k ? "enable" : "disable", name);
    for (const char *r = disable; r && (r = st_list_next(r, name, &optional));)
        if (name[0] && !disable_one(s, name, err)) return false;
    if (disable && disable[0] && !check_requires(s, disable, err)) return false;
    for (const char *r = enable; r && (r = st_list_next(r, name, &optional));)
        if (name[0] && !enable_one(s, name, name, 0, err)) return false;
    return true;
}
