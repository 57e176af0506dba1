// The frame graph: resource names interned per pass list, the pass list
// (slots) built from the modules' passes, and culling: a pass runs when a
// later live pass reads what it writes.
#include "st_world_state.h"
#include <stdio.h>
#include <string.h>

// Resource sets: names are interned once per pass list, frames work on bits.
static int res_id(st_world *w, const char *name) {
    for (int i = 0; i < w->num_res; i++)
        if (!strcmp(w->res[i], name)) return i;
    if (w->num_res == MAX_RESOURCES) return -1;
    snprintf(w->res[w->num_res], ST_NAME_MAX, "%s", name);
    return w->num_res++;
}

static bool res_parse(st_world *w, const char *list, st_resset *out, st_err *err) {
    memset(out, 0, sizeof *out);
    char tok[ST_NAME_MAX];
    for (const char *p = list; (p = st_list_next(p, tok, NULL));) {
        if (!tok[0]) continue;
        int id = res_id(w, tok);
        if (id < 0)
            return st_fail(err, ST_ERR_RUNTIME, "more than %d resource names in the passes",
                           MAX_RESOURCES);
        out->bits[id / 64] |= 1ull << (id % 64);
    }
    return true;
}

// Names resolve to indices here, when the pass list or the targets change;
// a frame reads the index (a `needed` hook may re-declare a target mid-frame).
static void resolve_target(st_world *w, st_slot *s) {
    s->target = st_targets_written(&w->targets, s->info.writes);
    s->target_gen = w->targets.gen;
}

int st_graph_target(st_world *w, st_slot *s) {
    if (s->target_gen != w->targets.gen) resolve_target(w, s);
    return s->target;
}

static bool add_slot(st_world *w, st_module_inst *mi, int pass, const st_pass_info *info,
                     st_err *err) {
    if (w->num_slots >= MAX_SLOTS)
        return st_fail(err, ST_ERR_RUNTIME, "too many passes (max %d)", MAX_SLOTS);
    st_slot *s = &w->slots[w->num_slots];
    memset(s, 0, sizeof *s);
    s->mod = mi;
    s->serial = mi ? mi->serial : 0;
    s->pass = pass;
    s->info = *info;
    if (!s->info.name) s->info.name = "pass";
    if (!s->info.reads) s->info.reads = "";
    if (!s->info.writes) s->info.writes = "";
    s->pending = ST_CHANGE_ALL;
    if (!res_parse(w, s->info.reads, &s->reads, err) ||
        !res_parse(w, s->info.writes, &s->writes, err))
        return false;
    resolve_target(w, s);
    const char *mname = mi ? mi->p->name : "world";
    char pname[ST_NAME_MAX];
    snprintf(pname, sizeof pname, "%s", s->info.name);
    // Passes of one module sharing a name (one per light) are numbered.
    if (mi) {
        int total = 0, ordinal = 0, n = st_passes_count(mi);
        for (int k = 0; k < n; k++) {
            const st_pass_info *o = st_passes_info(mi, k);
            if (!o || !o->name || strcmp(o->name, s->info.name)) continue;
            if (k < pass) ordinal++;
            total++;
        }
        if (total > 1) snprintf(pname, sizeof pname, "%s[%d]", s->info.name, ordinal);
    }
    st_pass_stats *ps = st_stats_entry(w, mname, pname);
    if (!ps) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    s->stats = (int)(ps - w->stats);
    // Timestamp pairs rather than GL_TIME_ELAPSED: llvmpipe reports a bogus
    // first elapsed time.
    if (w->opts.timing) glCreateQueries(GL_TIMESTAMP, 2, s->query);
    w->num_slots++;
    return true;
}

void st_graph_free(st_world *w) {
    for (int i = 0; i < w->num_slots; i++)
        if (w->slots[i].query[0]) glDeleteQueries(2, w->slots[i].query);
    w->num_slots = 0;
}

// Rebuilds the pass list: pre-passes in module order, the regular pass,
// post passes in module order. Pending changes of surviving passes carry over.
bool st_graph_build(st_world *w, st_err *err) {
    // Slots are matched by instance serial (0: the regular pass), never by
    // pointer: an unloaded instance's address may be reused by a new one.
    unsigned keep[MAX_SLOTS], keep_serial[MAX_SLOTS];
    int keep_pass[MAX_SLOTS], nkeep = w->num_slots;
    for (int i = 0; i < nkeep; i++) {
        keep[i] = w->slots[i].pending;
        keep_serial[i] = w->slots[i].serial;
        keep_pass[i] = w->slots[i].pass;
    }
    st_graph_free(w);
    w->num_res = 0;
    res_id(w, "hdr"); // RES_HDR
    w->regular_reads[0] = 0;
    for (int m = 0; m < w->num_mods; m++) {
        const st_plugin *p = w->mods[m]->p;
        if (p->regular_include && p->provides) {
            size_t l = strlen(w->regular_reads);
            snprintf(w->regular_reads + l, sizeof w->regular_reads - l, "%s%s", l ? "," : "",
                     p->provides);
        }
    }
    for (int stage = 0; stage < 3; stage++) {
        if (stage == 1) {
            st_pass_info reg = {"regular", ST_STAGE_PRE, w->regular_reads,
                                "hdr,gbuffer,albedo,depth", 0};
            if (!add_slot(w, NULL, 0, &reg, err)) return false;
            continue;
        }
        for (int m = 0; m < w->num_mods; m++) {
            st_module_inst *mi = w->mods[m];
            int n = st_passes_count(mi);
            for (int k = 0; k < n; k++) {
                const st_pass_info *info = st_passes_info(mi, k);
                if (!info)
                    return st_fail(err, ST_ERR_RUNTIME, "module '%s': no info for pass %d",
                                   mi->p->name, k);
                if ((stage == 0) != (info->stage == ST_STAGE_PRE)) continue;
                if (!add_slot(w, mi, k, info, err)) return false;
            }
        }
    }
    // A pass that existed before keeps what it had pending.
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        for (int k = 0; k < nkeep; k++)
            if (keep_serial[k] == s->serial && keep_pass[k] == s->pass) s->pending = keep[k];
    }
    return true;
}

void st_graph_cull(st_world *w, st_frame *f) {
    // Forward: which passes want to run; a pass that will rewrite a resource
    // marks its readers' inputs as changed.
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        const st_plugin *p = s->mod ? s->mod->p : NULL;
        f->changes = s->pending;
        st_passes_frame(s->mod, s->pass, f);
        s->needed = !p || !p->needed || p->needed(s->mod->self, s->pass, f);
        if (!s->needed) continue;
        for (int j = i + 1; j < w->num_slots; j++)
            if (st_resset_meet(&s->writes, &w->slots[j].reads))
                w->slots[j].pending |= ST_CHANGE_INPUTS;
    }
    // Backward: the final image is the root; a pass is live if a later live
    // pass reads what it writes. A skipped pass reads nothing this frame.
    st_resset live = {{1ull << RES_HDR}};
    for (int i = w->num_slots - 1; i >= 0; i--) {
        st_slot *s = &w->slots[i];
        s->live = (s->info.flags & ST_PASS_SIDE_EFFECT) || st_resset_meet(&s->writes, &live);
        if (s->live && s->needed) st_resset_add(&live, &s->reads);
    }
}
