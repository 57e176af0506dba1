// Modules in a world: load (parameters, light types), ordering by
// `requires`, instances, switching on and off, parameters, progress and
// shader reload.
#include "st_world_modules.h"
#include "st_world_regular.h"
#include "st_world_state.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int st_world_find_module(const st_world *w, const char *name) {
    for (int i = 0; i < w->num_mods; i++)
        if (!strcmp(w->mods[i]->p->name, name)) return i;
    return -1;
}

// Applies the scene's parameter settings for `name` onto defaults.
static bool init_params(st_world *w, st_module_inst *mi, st_err *err) {
    const st_plugin *p = mi->p;
    for (int i = 0; i < p->num_params; i++)
        mi->params[i] = p->params[i].def;
    const st_module_setting *ms = NULL;
    int idx = -1;
    for (int i = 0; i < w->scene->num_modules; i++)
        if (!strcmp(w->scene->modules[i].name, p->name)) ms = &w->scene->modules[idx = i];
    if (!ms) return true;
    for (int k = 0; k < ms->num_params; k++) {
        int pi = st_param_index(p, ms->params[k].name);
        if (pi < 0) {
            char names[512] = "";
            for (int i = 0; i < p->num_params; i++) {
                size_t l = strlen(names);
                snprintf(names + l, sizeof names - l, "%s%s", i ? ", " : "", p->params[i].name);
            }
            st_fail(err, ST_ERR_INPUT, "module '%s' has no parameter '%s' (it has: %s)", p->name,
                    ms->params[k].name, p->num_params ? names : "none");
        }
        if (pi < 0 || !st_param_from_value(p, pi, &ms->params[k].value, &mi->params[pi], err)) {
            // Blame what gave the value: a --set argument or the scene file's key.
            if (ms->params[k].set_arg[0])
                st_err_prefix(err, "--set %s: ", ms->params[k].set_arg);
            else
                st_err_prefix(err, "%s: modules[%d].params.%s: ", w->scene->path, idx,
                              ms->params[k].name);
            return false;
        }
    }
    return true;
}

void st_world_destroy_instance(st_module_inst *mi) {
    if (mi->self && mi->p->destroy) mi->p->destroy(mi->self);
    mi->self = NULL;
}

void st_world_unload(st_world *w, int m) {
    st_module_inst *mi = w->mods[m];
    st_world_destroy_instance(mi);
    st_passes_destroy(mi);
    st_targets_free(&w->targets, mi->p->name);
    st_plugin_close(mi->lib);
    free(mi);
    // Only the pointers move; the other instances stay where they are.
    memmove(&w->mods[m], &w->mods[m + 1], (size_t)(w->num_mods - m - 1) * sizeof w->mods[0]);
    w->num_mods--;
}

// A technique refuses a scene with a light type it cannot handle.
static bool check_lights(const st_world *w, const st_plugin *p, st_err *err) {
    unsigned ok = p->light_types ? p->light_types : ST_LIGHT_BIT(ST_LIGHT_POINT);
    for (int i = 0; i < w->scene->num_lights; i++) {
        st_light_type t = w->scene->lights[i].type;
        if (ok & ST_LIGHT_BIT(t)) continue;
        char list[64] = "";
        for (int k = 0; k < ST_LIGHT_TYPE_COUNT; k++)
            if (ok & ST_LIGHT_BIT(k))
                snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                         list[0] ? ", " : "", st_light_type_name((st_light_type)k));
        return st_fail(err, ST_ERR_INPUT,
                       "%s: lights[%d]: module '%s' does not support %s lights (it supports: %s)",
                       w->scene->path, i, p->name, st_light_type_name(t), list);
    }
    return true;
}

// Loads module `name` with its parameters; `order` check happens in resolve.
bool st_world_load(st_world *w, const char *name, st_err *err) {
    if (w->num_mods >= MAX_MODULES)
        return st_fail(err, ST_ERR_INPUT, "too many modules (max %d)", MAX_MODULES);
    st_module_inst *mi = calloc(1, sizeof *mi);
    if (!mi) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    mi->lib = st_plugin_open(name, err);
    if (!mi->lib) {
        free(mi);
        return false;
    }
    mi->p = st_plugin_desc(mi->lib);
    if (!check_lights(w, mi->p, err) || !init_params(w, mi, err)) {
        st_plugin_close(mi->lib);
        free(mi);
        return false;
    }
    mi->serial = ++w->next_serial;
    w->mods[w->num_mods++] = mi;
    return true;
}

// Two techniques that compute the medium's in-scattering add it twice: the
// image is not a physical one (issue 37). Refused unless the scene opts in.
static bool check_inscatter(const st_world *w, st_err *err) {
    int first = -1;
    for (int i = 0; i < w->num_mods; i++) {
        if (!st_list_has(w->mods[i]->p->provides, ST_CAP_INSCATTER)) continue;
        if (first < 0) {
            first = i;
        } else if (!w->scene->inscatter_overlay) {
            return st_fail(err, ST_ERR_INPUT,
                           "%s: modules '%s' and '%s' both compute the medium's in-scattering and "
                           "would add it twice; keep one (--disable %s or --disable %s), or "
                           "overlay both for a "
                           "comparison with \"inscatter_overlay\": true in the scene (--overlay)",
                           w->scene->path, w->mods[first]->p->name, w->mods[i]->p->name,
                           w->mods[first]->p->name, w->mods[i]->p->name);
        }
    }
    return true;
}

// Orders modules so each comes after the providers of what it requires
// (a requirement "name?" is optional: it only orders).
bool st_world_resolve(st_world *w, st_err *err) {
    if (!check_inscatter(w, err)) return false;
    st_module_inst *sorted[MAX_MODULES];
    bool placed[MAX_MODULES] = {0};
    int n = 0;
    while (n < w->num_mods) {
        bool progress = false;
        for (int i = 0; i < w->num_mods; i++) {
            if (placed[i]) continue;
            bool ok = true, optional;
            char tmp[ST_NAME_MAX];
            for (const char *r = w->mods[i]->p->requires;
                 ok && (r = st_list_next(r, tmp, &optional));) {
                if (!tmp[0]) continue;
                // "name?" is optional: after its provider when one is loaded.
                bool found = false, any = false;
                for (int j = 0; j < w->num_mods; j++) {
                    if (j == i || !st_list_has(w->mods[j]->p->provides, tmp)) continue;
                    any = true;
                    found |= placed[j];
                }
                if (!any && !optional)
                    return st_fail(
                        err, ST_ERR_INPUT,
                        "%s: module '%s' requires '%s', which no module in the scene provides "
                        "(add {\"name\": \"%s\"} to modules)",
                        w->scene->path, w->mods[i]->p->name, tmp, tmp);
                ok = found || (!any && optional);
            }
            if (!ok) continue;
            sorted[n++] = w->mods[i];
            placed[i] = true;
            progress = true;
        }
        if (!progress)
            return st_fail(err, ST_ERR_INPUT, "%s: modules require each other in a cycle",
                           w->scene->path);
    }
    memcpy(w->mods, sorted, (size_t)n * sizeof sorted[0]);
    return true;
}

bool st_world_instantiate(st_world *w, int m, st_err *err) {
    st_module_inst *mi = w->mods[m];
    if (mi->self) return true;
    // A plugin with declared passes and no state of its own has no create:
    // its instance is its parameter array (never NULL, never dereferenced).
    mi->self = mi->p->create ? mi->p->create(w, mi->params, err) : (void *)mi->params;
    if (!mi->self) {
        st_err_prefix(err, "module '%s': ", mi->p->name);
        return false;
    }
    if (!st_passes_create(w, mi, err)) { // destroyed with the instance
        st_err_prefix(err, "module '%s': ", mi->p->name);
        return false;
    }
    mi->num_uniforms = mi->p->uniforms ? mi->p->uniforms(mi->self, &mi->uniforms) : 0;
    mi->params_dirty = true;
    return true;
}

bool st_world_has_module(const st_world *w, const char *module) {
    return st_world_find_module(w, module) >= 0;
}

bool st_world_enable(st_world *w, const char *module, bool on, st_err *err) {
    int m = st_world_find_module(w, module);
    if (on == (m >= 0)) return true;
    if (on && !st_medium_gpu_check_module(w->scene, module, err)) return false;
    unsigned before = w->next_serial; // instances with a larger serial are this call's
    if (on) {
        if (!st_world_load(w, module, err)) return false;
        // Load what it requires first (turning on toth turns on shadow_map).
        const char *req = w->mods[w->num_mods - 1]->p->requires;
        char tmp[ST_NAME_MAX];
        bool optional;
        for (const char *r = req; (r = st_list_next(r, tmp, &optional));) {
            if (!tmp[0] || optional) continue; // optional requirements are not loaded
            bool have = false;
            for (int j = 0; j < w->num_mods; j++)
                have |= st_list_has(w->mods[j]->p->provides, tmp);
            if (!have && !st_world_load(w, tmp, err)) {
                for (int i = w->num_mods - 1; i >= 0; i--) // everything this call loaded
                    if (w->mods[i]->serial > before) st_world_unload(w, i);
                return false;
            }
        }
    } else {
        // Refuse to remove a provider others still need.
        // (An optional requirement "name?" does not hold it.)
        char tmp[ST_NAME_MAX];
        bool optional;
        for (int j = 0; j < w->num_mods; j++)
            for (const char *r = w->mods[j]->p->requires;
                 j != m && (r = st_list_next(r, tmp, &optional));)
                if (tmp[0] && !optional && st_list_has(w->mods[m]->p->provides, tmp))
                    return st_fail(err, ST_ERR_INPUT, "module '%s' is required by '%s'", module,
                                   w->mods[j]->p->name);
        st_world_destroy_instance(w->mods[m]);
        st_world_unload(w, m);
    }
    bool ok = st_world_resolve(w, err);
    for (int i = 0; ok && i < w->num_mods; i++)
        ok = st_world_instantiate(w, i, err);
    ok = ok && st_world_build_regular(w, err);
    if (!ok && on) {
        // A module (or its regular include) failed: unload what this call
        // loaded; the regular shader is only replaced on success.
        for (int i = w->num_mods - 1; i >= 0; i--) {
            if (w->mods[i]->serial > before) st_world_unload(w, i);
        }
    }
    // The pass list always follows the module list, also after a failure.
    st_err ignore = {0};
    if (!st_graph_build(w, ok ? err : &ignore)) ok = false;
    w->changes |= ST_CHANGE_CAMERA;
    return ok;
}

bool st_world_set_param(st_world *w, const char *module, const char *param, double value,
                        st_err *err) {
    int m = st_world_find_module(w, module);
    if (m < 0) return st_fail(err, ST_ERR_INPUT, "module '%s' is not loaded", module);
    st_module_inst *mi = w->mods[m];
    int k = st_param_index(mi->p, param);
    if (k < 0)
        return st_fail(err, ST_ERR_INPUT, "module '%s' has no parameter '%s'", module, param);
    const st_param_def *d = &mi->p->params[k];
    if (!isfinite(value))
        return st_fail(err, ST_ERR_INPUT, "%s.%s: not a finite number", module, param);
    if (d->type == ST_PARAM_FLOAT || d->type == ST_PARAM_INT) {
        if (value < d->min || value > d->max)
            return st_fail(err, ST_ERR_INPUT, "%s.%s: %.9g is out of range [%g, %g]", module, param,
                           value, d->min, d->max);
        if (d->type == ST_PARAM_INT) value = floor(value + 0.5);
    } else if (d->type == ST_PARAM_BOOL) {
        value = value != 0;
    } else {
        int nchoices = st_param_num_choices(d);
        if (value < 0 || value >= nchoices || value != floor(value))
            return st_fail(err, ST_ERR_INPUT, "%s.%s: choice %.9g out of range", module, param,
                           value);
    }
    if (mi->params[k] == value) return true;
    if (!st_passes_param_programs(w, mi, k, value, err)) {
        st_err_prefix(err, "%s.%s: ", module, param);
        return false;
    }
    mi->params[k] = value;
    mi->params_dirty = true;
    if (mi->p->param_changed) mi->p->param_changed(mi->self, k);
    if (!st_passes_declare_targets(w, mi, err)) return false;
    // A parameter may change a module's pass list (e.g. interleave on/off).
    return st_graph_build(w, err);
}

bool st_world_get_param(const st_world *w, const char *module, const char *param, double *value) {
    int m = st_world_find_module(w, module);
    if (m < 0) return false;
    int k = st_param_index(w->mods[m]->p, param);
    if (k < 0) return false;
    *value = w->mods[m]->params[k];
    return true;
}

bool st_world_progress(const st_world *w, st_progress *out) {
    *out = (st_progress){.converged = true};
    bool any = false;
    for (int i = 0; i < w->num_mods; i++) {
        if (!w->mods[i]->p->progress) continue;
        st_progress p = {0};
        if (!w->mods[i]->p->progress(w->mods[i]->self, &p)) continue;
        any = true;
        out->converged = out->converged && p.converged;
        if (p.frames > out->frames) out->frames = p.frames;
        if (p.error > out->error || isnan(p.error)) out->error = p.error;
        if (p.info[0]) {
            size_t n = strlen(out->info);
            snprintf(out->info + n, sizeof out->info - n, "%s%s: %s", n ? "; " : "",
                     w->mods[i]->p->name, p.info);
        }
    }
    if (w->opts.filter == ST_FILTER_BOX) { // the pixel filter converges too
        any = true;
        out->converged = out->converged && w->acc_done;
        if (w->acc_n > out->frames) out->frames = w->acc_n;
        if (w->acc_err > out->error || isnan(w->acc_err)) out->error = w->acc_err;
        size_t n = strlen(out->info);
        snprintf(out->info + n, sizeof out->info - n,
                 "%sfilter: box, %u frame(s) accumulated, estimated NRMSE %.4g", n ? "; " : "",
                 w->acc_n, w->acc_err);
    }
    return any;
}

bool st_world_reload_shaders(st_world *w, st_err *err) {
    // Rebuilt for the current module list (a switch made while the file was
    // broken left the old program); the old one stays on failure.
    if (!st_world_build_regular(w, err)) return false;
    for (int m = 0; m < w->num_mods; m++) {
        st_module_inst *mi = w->mods[m];
        if (!st_passes_reload(mi, err) || (mi->p->reload && !mi->p->reload(mi->self, err))) {
            st_err_prefix(err, "module '%s': ", mi->p->name);
            return false;
        }
    }
    w->changes |= ST_CHANGE_CAMERA | ST_CHANGE_PROGRAMS;
    return true;
}
