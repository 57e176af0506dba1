// strahl view: which plugins the G (god rays) and I (GI display) keys
// switch, from what each plugin's descriptor declares, so that the viewer
// names no plugin and a new technique joins its key without a change here:
//   GI display: a plugin whose light joins the regular pass (it has a
//     regular_include) and that has a display switch with an "indirect"
//     choice (today atlas_gi). The first such plugin by name is the I key's.
//   god rays: a plugin that only adds light to the image: no
//     regular_include, it provides no capability to others (ST_CAP_INSCATTER,
//     which says that it adds the medium's in-scattered light, is not one)
//     and has no display switch (today froxel, mitchell, sousa, toth). G
//     cycles off, then these by name.
//   anything else (shadow_map provides shadows, ssgi shows its indirect
//   light on its own) has only its number key.
#include "view.h"
#include "st_list.h"
#include <stdio.h>
#include <string.h>

int view_gi_display_param(const st_plugin *p) {
    for (int i = 0; i < p->num_params; i++) {
        const st_param_def *d = &p->params[i];
        if (d->type != ST_PARAM_ENUM) continue;
        for (int k = 0; k < st_param_num_choices(d); k++) {
            char c[ST_NAME_MAX];
            st_param_choice(d, k, c, sizeof c);
            if (!strcmp(c, "indirect")) return i;
        }
    }
    return -1;
}

// Does p provide a capability that other modules may require?
static bool provides_to_others(const st_plugin *p) {
    char cap[ST_NAME_MAX];
    for (const char *r = p->provides; (r = st_list_next(r, cap, NULL));)
        if (cap[0] && strcmp(cap, ST_CAP_INSCATTER)) return true;
    return false;
}

view_kind view_plugin_kind(const st_plugin *p) {
    bool display = view_gi_display_param(p) >= 0;
    bool include = p->regular_include && p->regular_include[0];
    bool provides = provides_to_others(p);
    if (include && display) return VIEW_KIND_GI;
    if (!include && !provides && !display) return VIEW_KIND_GODRAYS;
    return VIEW_KIND_OTHER;
}

// The kind of module `name`: from the loaded instance's descriptor, else
// from the installed plugin's (opened for the look and closed again); a
// plugin that does not open has no kind.
static view_kind kind_of(const view *v, const char *name) {
    for (int i = 0; i < st_world_num_modules(v->world); i++) {
        const st_plugin *p = st_world_module(v->world, i).plugin;
        if (!strcmp(p->name, name)) return view_plugin_kind(p);
    }
    st_err ignore = {0};
    st_plugin_lib *lib = st_plugin_open(name, &ignore);
    if (!lib) return VIEW_KIND_OTHER;
    view_kind k = view_plugin_kind(st_plugin_desc(lib));
    st_plugin_close(lib);
    return k;
}

void view_classify_modules(view *v) {
    v->num_godrays = 0;
    snprintf(v->godrays[v->num_godrays++], ST_NAME_MAX, "off");
    v->gi_module[0] = 0;
    // v->mods is sorted by name.
    for (int i = 0; i < v->num_mods; i++) {
        view_kind k = kind_of(v, v->mods[i]);
        if (k == VIEW_KIND_GODRAYS && v->num_godrays < VIEW_MAX_MODS + 1)
            snprintf(v->godrays[v->num_godrays++], ST_NAME_MAX, "%s", v->mods[i]);
        else if (k == VIEW_KIND_GI && !v->gi_module[0])
            snprintf(v->gi_module, ST_NAME_MAX, "%s", v->mods[i]);
    }
}
