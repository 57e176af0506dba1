// Declared passes (st_pass_decl, ABI 1.3): the world expands a plugin's
// table into passes (one per light for ST_PER_LIGHT rows), loads, reloads and
// destroys their programs, declares their targets (again when the parameter
// that scales them changes) and sets parameters as uniforms. A plugin
// without a table answers num_passes/pass_info itself; both kinds meet here.
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
    if (!mi->p->passes) return true;
    return expand_table(w, mi, err) && load_programs(mi, err) &&
           st_passes_declare_targets(w, mi, err);
}

void st_passes_destroy(st_module_inst *mi) {
    for (int r = 0; mi->decl_sh && r < mi->p->num_pass_decls; r++)
        st_shader_destroy(mi->decl_sh[r]);
    free(mi->decl_sh);
    free(mi->decl);
    mi->decl_sh = NULL;
    mi->decl = NULL;
    mi->num_decl = 0;
}

bool st_passes_reload(st_module_inst *mi, st_err *err) {
    for (int r = 0; mi->decl_sh && r < mi->p->num_pass_decls; r++)
        if (mi->decl_sh[r] && !st_shader_reload(mi->decl_sh[r], err)) return false;
    return true;
}

st_shader *st_passes_shader(const st_module_inst *mi, int k) {
    if (mi->p->passes && mi->decl_sh[mi->decl[k].row]) return mi->decl_sh[mi->decl[k].row];
    return mi->p->shader ? mi->p->shader(mi->self, k) : NULL;
}

void st_passes_frame(const st_module_inst *mi, int k, st_frame *f) {
    bool d = mi && mi->p->passes;
    f->params = mi ? mi->params : NULL;
    f->shader = d ? mi->decl_sh[mi->decl[k].row] : NULL;
    f->row = d ? mi->decl[k].row : 0;
    f->instance = d ? mi->decl[k].instance : 0;
}

void st_passes_set_params(const st_module_inst *mi, st_shader *sh) {
    const char *prefix = mi->p->param_uniforms;
    for (int i = 0; prefix && sh && i < mi->p->num_params; i++) {
        char name[2 * ST_NAME_MAX];
        snprintf(name, sizeof name, "%s%s", prefix, mi->p->params[i].name);
        GLint loc = st_shader_loc(sh, name);
        if (loc < 0) continue;
        GLuint index = glGetProgramResourceIndex(sh->program, GL_UNIFORM, name);
        const GLenum prop = GL_TYPE;
        GLint type = 0;
        glGetProgramResourceiv(sh->program, GL_UNIFORM, index, 1, &prop, 1, NULL, &type);
        if (type == GL_FLOAT) glUniform1f(loc, (float)mi->params[i]);
        if (type == GL_INT || type == GL_BOOL) glUniform1i(loc, (int)mi->params[i]);
    }
}
