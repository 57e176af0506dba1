// Declared passes (st_pass_decl, ABI 1.3): the world expands a plugin's
// table into passes (one per light for ST_PER_LIGHT rows), loads, reloads and
// destroys their programs, declares their targets (again when the parameter
// that scales them changes) and sets parameters as uniforms. Declared
// programs (ABI 1.4) are compiled on first use, with the parameters they
// name as defines, and recompiled when one of those changes; exports set a
// module's parameters and targets on every program. A plugin without a table
// answers num_passes/pass_info itself; both kinds meet here.
#include "st_world_state.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int st_passes_count(const st_module_inst *mi) {
    return mi->p->passes ? mi->num_decl : mi->p->num_passes(mi->self);
}

const st_pass_info *st_passes_info(const st_module_inst *mi, int k) {
    return mi->p->passes ? &mi->decl[k].info : mi->p->pass_info(mi->self, k);
}

// `s` with its first "%d" replaced by k (no format string reaches printf).
static void expand(const char *s, int k, char *out, size_t n) {
    const char *at = s ? strstr(s, "%d") : NULL;
    if (!at)
        snprintf(out, n, "%s", s ? s : "");
    else
        snprintf(out, n, "%.*s%d%s", (int)(at - s), s, k, at + 2);
}

static int instances(const st_world *w, const st_pass_decl *d) {
    if (d->count != ST_PER_LIGHT) return 1;
    return w->num_lights < ST_MAX_LIGHTS ? w->num_lights : ST_MAX_LIGHTS;
}

static bool expand_table(st_world *w, st_module_inst *mi, st_err *err) {
    const st_plugin *p = mi->p;
    size_t n = 1;
    for (int r = 0; r < p->num_pass_decls; r++)
        n += (size_t)instances(w, &p->passes[r]);
    mi->decl = calloc(n, sizeof *mi->decl);
    mi->decl_sh = calloc((size_t)p->num_pass_decls + 1, sizeof *mi->decl_sh);
    if (!mi->decl || !mi->decl_sh) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int r = 0; r < p->num_pass_decls; r++) {
        const st_pass_decl *d = &p->passes[r];
        for (int k = 0; k < instances(w, d); k++) {
            st_decl_pass *e = &mi->decl[mi->num_decl++];
            e->row = r;
            e->instance = k;
            e->info = d->info;
            expand(d->info.reads, k, e->reads, sizeof e->reads);
            expand(d->info.writes, k, e->writes, sizeof e->writes);
            e->info.reads = e->reads;
            e->info.writes = e->writes;
        }
    }
    return true;
}

static int program_index(const st_plugin *p, const char *name) {
    for (int i = 0; name && i < p->num_programs; i++)
        if (!strcmp(p->programs[i].name, name)) return i;
    return -1;
}

// The defines of program k for parameter values `params`: the light defines
// (ST_PROGRAM_LIGHTS), the fixed ones, then "<MODULE>_<PARAM> <value>" per
// parameter it names.
static bool program_defines(st_world *w, const st_plugin *p, int k, const double *params, char *out,
                            size_t n, st_err *err) {
    const st_program_decl *d = &p->programs[k];
    size_t l =
        (size_t)snprintf(out, n, "%s%s%s", d->flags & ST_PROGRAM_LIGHTS ? w->light_defines : "",
                         d->defines ? d->defines : "", d->defines ? "\n" : "");
    char tok[ST_NAME_MAX];
    for (const char *s = d->param_defines; l < n && (s = st_list_next(s, tok, NULL));) {
        int i = tok[0] ? st_param_index(p, tok) : -1;
        if (i < 0) continue; // the loader refused unknown names
        char name[2 * ST_NAME_MAX];
        snprintf(name, sizeof name, "%s_%s", p->name, tok);
        for (char *c = name; *c; c++)
            *c = (char)(*c >= 'a' && *c <= 'z' ? *c - 'a' + 'A' : *c);
        if (p->params[i].type == ST_PARAM_FLOAT)
            l += (size_t)snprintf(out + l, n - l, "%s %.9g\n", name, params[i]);
        else
            l += (size_t)snprintf(out + l, n - l, "%s %d\n", name, (int)params[i]);
    }
    if (l >= n) return st_fail(err, ST_ERR_RUNTIME, "program '%s': defines too long", d->name);
    return true;
}

static st_shader *compile(st_world *w, const st_plugin *p, int k, const double *params,
                          st_err *err) {
    const st_program_decl *d = &p->programs[k];
    char defs[2048];
    if (!program_defines(w, p, k, params, defs, sizeof defs, err)) return NULL;
    if (d->comp) return st_shader_load_compute(d->comp, defs, err);
    return st_shader_load(d->vert ? d->vert : "common/fullscreen.vert", d->frag, defs, err);
}

static st_shader *program(st_world *w, st_module_inst *mi, int k, st_err *err) {
    if (k < 0 || k >= mi->p->num_programs) {
        st_fail(err, ST_ERR_RUNTIME, "module '%s': no program %d", mi->p->name, k);
        return NULL;
    }
    // The table exists from the first use on: st_world_program may be called
    // from create, before the world sets up the module's passes.
    if (!mi->progs)
        mi->progs = st_calloc(((size_t)mi->p->num_programs + 1) * sizeof *mi->progs, err);
    if (!mi->progs) return NULL;
    if (!mi->progs[k]) mi->progs[k] = compile(w, mi->p, k, mi->params, err);
    return mi->progs[k];
}

// ABI 1.4: the program table, each row's program (compiled now, so a broken
// file is reported when the module loads) and each export's parameter.
static bool create_programs(st_world *w, st_module_inst *mi, st_err *err) {
    const st_plugin *p = mi->p;
    if (!mi->progs) mi->progs = calloc((size_t)p->num_programs + 1, sizeof *mi->progs);
    mi->row_prog = calloc((size_t)p->num_pass_decls + 1, sizeof *mi->row_prog);
    mi->export_param = calloc((size_t)p->num_exports + 1, sizeof *mi->export_param);
    if (!mi->progs || !mi->row_prog || !mi->export_param)
        return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int i = 0; i < p->num_exports; i++)
        mi->export_param[i] = p->exports[i].param ? st_param_index(p, p->exports[i].param) : -1;
    for (int r = 0; r < p->num_pass_decls; r++) {
        mi->row_prog[r] = program_index(p, p->passes[r].program);
        if (mi->row_prog[r] >= 0 && !program(w, mi, mi->row_prog[r], err)) return false;
    }
    return true;
}

static bool load_programs(st_module_inst *mi, st_err *err) {
    for (int r = 0; r < mi->p->num_pass_decls; r++) {
        const st_pass_decl *d = &mi->p->passes[r];
        if (!d->frag) continue;
        const char *vert = d->vert ? d->vert : "common/fullscreen.vert";
        if (!(mi->decl_sh[r] = st_shader_load(vert, d->frag, d->defines, err))) return false;
    }
    return true;
}

bool st_passes_declare_targets(st_world *w, st_module_inst *mi, st_err *err) {
    for (int i = 0; i < mi->num_decl; i++) {
        const st_pass_decl *d = &mi->p->passes[mi->decl[i].row];
        if (!d->target.format) continue;
        st_target_desc desc = d->target;
        int k = d->scale_param ? st_param_index(mi->p, d->scale_param) : -1;
        if (d->scale_param && k < 0)
            return st_fail(err, ST_ERR_INPUT, "pass '%s': no parameter '%s' to scale its target",
                           d->info.name ? d->info.name : "?", d->scale_param);
        if (k >= 0) desc.scale = mi->params[k];
        if (!st_world_declare_target(w, mi->decl[i].writes, &desc, err)) return false;
    }
    return true;
}

bool st_passes_create(st_world *w, st_module_inst *mi, st_err *err) {
    if (!create_programs(w, mi, err)) return false;
    if (!mi->p->passes) return true;
    return expand_table(w, mi, err) && load_programs(mi, err) &&
           st_passes_declare_targets(w, mi, err);
}

void st_passes_destroy(st_module_inst *mi) {
    for (int r = 0; mi->decl_sh && r < mi->p->num_pass_decls; r++)
        st_shader_destroy(mi->decl_sh[r]);
    for (int k = 0; mi->progs && k < mi->p->num_programs; k++)
        st_shader_destroy(mi->progs[k]);
    free(mi->decl_sh);
    free(mi->decl);
    free(mi->progs);
    free(mi->row_prog);
    free(mi->export_param);
    mi->decl_sh = mi->progs = NULL;
    mi->row_prog = mi->export_param = NULL;
    mi->decl = NULL;
    mi->num_decl = 0;
}

bool st_passes_reload(st_module_inst *mi, st_err *err) {
    for (int r = 0; mi->decl_sh && r < mi->p->num_pass_decls; r++)
        if (mi->decl_sh[r] && !st_shader_reload(mi->decl_sh[r], err)) return false;
    for (int k = 0; mi->progs && k < mi->p->num_programs; k++)
        if (mi->progs[k] && !st_shader_reload(mi->progs[k], err)) return false;
    return true;
}

bool st_passes_param_programs(st_world *w, st_module_inst *mi, int k, double value, st_err *err) {
    const st_plugin *p = mi->p;
    st_shader *fresh[ST_MAX_PROGRAMS] = {0};
    double params[ST_MAX_PARAMS];
    memcpy(params, mi->params, sizeof params);
    params[k] = value;
    bool ok = true;
    for (int i = 0; ok && i < p->num_programs && i < ST_MAX_PROGRAMS; i++) {
        if (!mi->progs[i] || !st_list_has(p->programs[i].param_defines, p->params[k].name))
            continue;
        ok = (fresh[i] = compile(w, p, i, params, err)) != NULL;
    }
    for (int i = 0; i < p->num_programs && i < ST_MAX_PROGRAMS; i++) {
        if (!fresh[i]) continue;
        if (ok) st_shader_destroy(mi->progs[i]);
        if (ok)
            mi->progs[i] = fresh[i];
        else
            st_shader_destroy(fresh[i]);
    }
    return ok;
}

bool st_passes_shader(st_world *w, st_module_inst *mi, int k, const st_frame *f, st_shader **out,
                      st_err *err) {
    const st_plugin *p = mi->p;
    int r = p->passes ? mi->decl[k].row : -1;
    int prog = p->program ? p->program(mi->self, k, f) : r >= 0 ? mi->row_prog[r] : -1;
    *out = NULL;
    if (prog >= 0) return (*out = program(w, mi, prog, err)) != NULL;
    if (p->program || (r >= 0 && p->passes[r].program)) return true; // the plugin draws itself
    if (r >= 0 && mi->decl_sh[r])
        *out = mi->decl_sh[r];
    else if (p->shader)
        *out = p->shader(mi->self, k);
    return true;
}

bool st_passes_owns(const st_module_inst *mi, const st_shader *sh) {
    for (int k = 0; sh && mi->progs && k < mi->p->num_programs; k++)
        if (mi->progs[k] == sh) return true;
    return false;
}

// A parameter's value on a uniform of the GLSL type the program declares.
static void set_value(st_shader *sh, const char *name, GLint loc, double v) {
    GLuint index = glGetProgramResourceIndex(sh->program, GL_UNIFORM, name);
    const GLenum prop = GL_TYPE;
    GLint type = 0;
    glGetProgramResourceiv(sh->program, GL_UNIFORM, index, 1, &prop, 1, NULL, &type);
    if (type == GL_FLOAT) glUniform1f(loc, (float)v);
    if (type == GL_INT || type == GL_BOOL) glUniform1i(loc, (int)v);
}

void st_passes_apply_exports(st_world *w, st_shader *sh) {
    for (int m = 0; m < w->num_mods; m++) {
        const st_module_inst *mi = w->mods[m];
        for (int i = 0; mi->export_param && i < mi->p->num_exports; i++) {
            const st_export_decl *e = &mi->p->exports[i];
            GLint loc = st_shader_loc(sh, e->uniform);
            if (loc < 0) continue;
            if (mi->export_param[i] >= 0) {
                set_value(sh, e->uniform, loc, mi->params[mi->export_param[i]]);
                continue;
            }
            const st_target *t = st_world_target(w, e->target);
            GLuint buf_tex = t ? 0 : st_targets_object(&w->targets, e->target, GL_TEXTURE);
            if (buf_tex)
                st_shader_texture(sh, e->uniform, GL_TEXTURE_BUFFER, buf_tex);
            else
                st_shader_texture(sh, e->uniform, t ? t->type : GL_TEXTURE_2D, t ? t->color[0] : 0);
        }
    }
}

// The module whose parameter array is `params`, and its program k.
st_shader *st_passes_program_of(st_world *w, const double *params, int k, st_module_inst **out,
                                st_err *err) {
    *out = NULL;
    for (int m = 0; m < w->num_mods && !*out; m++)
        if (w->mods[m]->params == params) *out = w->mods[m];
    if (!*out) {
        st_fail(err, ST_ERR_RUNTIME, "not a module's parameters (st_frame.params or create's)");
        return NULL;
    }
    return program(w, *out, k, err);
}

st_shader *st_world_program(st_world *w, const double *params, int k, st_err *err) {
    st_module_inst *mi;
    return st_passes_program_of(w, params, k, &mi, err);
}

void st_passes_frame(const st_module_inst *mi, int k, st_frame *f) {
    bool d = mi && mi->p->passes;
    f->params = mi ? mi->params : NULL;
    f->shader = d ? mi->decl_sh[mi->decl[k].row] : NULL;
    if (d && !f->shader && mi->row_prog[mi->decl[k].row] >= 0)
        f->shader = mi->progs[mi->row_prog[mi->decl[k].row]];
    f->row = d ? mi->decl[k].row : 0;
    f->instance = d ? mi->decl[k].instance : 0;
}

void st_passes_set_params(const st_module_inst *mi, st_shader *sh) {
    const char *prefix = mi->p->param_uniforms;
    for (int i = 0; prefix && sh && i < mi->p->num_params; i++) {
        char name[2 * ST_NAME_MAX];
        snprintf(name, sizeof name, "%s%s", prefix, mi->p->params[i].name);
        GLint loc = st_shader_loc(sh, name);
        if (loc >= 0) set_value(sh, name, loc, mi->params[i]);
    }
}
