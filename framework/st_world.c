// The World: owns the scene's GPU data, the camera, the loaded modules and
// the frame graph. Each frame: pre-passes, the regular pass, then the
// PostProcessor chain; passes nobody consumes are culled, passes whose
// inputs did not change are skipped (their cached output stays valid).
#define _POSIX_C_SOURCE 200809L
#include "st_world.h"
#include "st_physics.h"
#include "st_medium_gpu.h" /* hook: medium */
#include "st_targets.h"
#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_MODULES 16
#define MAX_SLOTS 128
#define MAX_RESOURCES 128 // distinct resource names in one pass list

// A set of resources, by id (index into st_world.res).
typedef struct st_resset {
    uint64_t bits[MAX_RESOURCES / 64];
} st_resset;

// A loaded module. Each instance is its own heap block, created by load() and
// freed by unload(), so `params` (handed to the plugin's create) and `self`
// stay at one address for the instance's whole life, whatever the module
// list does around it.
typedef struct st_module_inst {
    st_plugin_lib *lib;
    const st_plugin *p;
    void *self;
    double params[ST_MAX_PARAMS];
    const st_uniform *uniforms;
    int num_uniforms;
    bool params_dirty;
    unsigned serial; // unique per world: identifies the instance across pass-list rebuilds
} st_module_inst;

// One pass in frame order. mod == NULL is the world's regular pass.
typedef struct st_slot {
    st_module_inst *mod; // dangling between an unload and the next build_slots
    unsigned serial;     // mod's serial (0: regular), readable even then
    int pass;
    st_pass_info info;
    st_resset reads, writes; // info.reads/writes as ids
    unsigned pending;        // changes since the pass last ran
    bool needed, live;
    GLuint query[2]; // GL_TIMESTAMP before and after
    int stats;
} st_slot;

struct st_world {
    const st_scene *scene;
    st_world_opts opts;
    st_camera cam;
    st_model_type type;
    st_model *models;
    int num_models;
    st_shader *regular;
    st_shader *background;             // the background seen through a medium (scenes with one)
    char light_defines[64];            // st_world_light_defines
    st_medium_gpu medium;              /* hook: medium (the density on the GPU) */
    st_module_inst *mods[MAX_MODULES]; // one heap block per instance: never moves
    unsigned next_serial;
    int num_mods;
    st_slot slots[MAX_SLOTS];
    int num_slots;
    st_pass_stats *stats;
    int num_stats, cap_stats;
    uint64_t frame;
    unsigned changes; // accumulated since the last frame
    float light_pos[ST_MAX_LIGHTS][3], light_int[ST_MAX_LIGHTS][3];
    float light_dir[ST_MAX_LIGHTS][3], light_shape[ST_MAX_LIGHTS][3]; // see common/uniforms.glsl
    int light_type[ST_MAX_LIGHTS];
    int num_lights;
    char regular_reads[512];              // what the regular pass consumes
    char res[MAX_RESOURCES][ST_NAME_MAX]; // resource names, interned per pass list; 0 is "hdr"
    int num_res;
    st_targets targets; // declared and tracked by modules (st_world_declare_target)
    // The box pixel filter (st_world_opts.filter): jittered projection of this
    // frame, the running sums' state and its convergence.
    st_shader *accumulate;
    float jitter[2];                             // this frame's offset, pixels
    float jit_proj[16], jit_vp[16], jit_ivp[16]; // the camera's matrices, jittered
    int acc_cur;                                 // accum target holding the sums
    uint32_t acc_n;                              // frames in the sums (0: restart)
    bool acc_done;                               // converged or capped: later frames add nothing
    double acc_err;                              // relative standard error of the mean image
    float *acc_read;                             // read-back buffer for the convergence test
    int acc_stats;                               // stats entry "world/accumulate"
};

// ---- builtin uniforms (thesis: Camera and Light are uniform providers) ----

#define W(self) ((st_world *)(self))
static void u_view(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->view);
}
static void u_proj(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->proj);
}
static void u_vp(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->view_proj);
}
static void u_ivp(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniformMatrix4fv(l, 1, 0, f->inv_view_proj);
}
static void u_cam(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform3fv(l, 1, f->cam_pos);
}
static void u_near(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, f->near_z);
}
static void u_far(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, f->far_z);
}
static void u_fov(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, glm_rad(f->fov_y));
}
static void u_res(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform2f(l, (float)f->width, (float)f->height);
}
static void u_frame(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, (int)(f->index & 0x7fffffff));
}
static void u_nl(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, W(s)->num_lights);
}
static void u_lp(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_pos[0][0]);
}
static void u_li(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_int[0][0]);
}
static void u_lt(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform1iv(l, W(s)->num_lights, W(s)->light_type);
}
static void u_ld(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_dir[0][0]);
}
static void u_lshape(void *s, st_shader *sh, GLint l, const st_frame *f) {
    if (W(s)->num_lights) glUniform3fv(l, W(s)->num_lights, &W(s)->light_shape[0][0]);
}
static void u_hasmed(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, f->scene->medium.present);
}
static void u_ss(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform3fv(l, 1, f->scene->medium.sigma_s);
}
static void u_sa(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform3fv(l, 1, f->scene->medium.sigma_a);
}
static void u_pk(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1i(l, (int)f->scene->medium.phase);
}
static void u_pg(void *s, st_shader *sh, GLint l, const st_frame *f) {
    glUniform1f(l, f->scene->medium.g);
}

static const st_uniform builtin_uniforms[] = {
    {"st_view", u_view},
    {"st_proj", u_proj},
    {"st_view_proj", u_vp},
    {"st_inv_view_proj", u_ivp},
    {"st_cam_pos", u_cam},
    {"st_near", u_near},
    {"st_far", u_far},
    {"st_fov_y", u_fov},
    {"st_resolution", u_res},
    {"st_frame_index", u_frame},
    {"st_num_lights", u_nl},
    {"st_light_pos", u_lp},
    {"st_light_intensity", u_li},
    {"st_has_medium", u_hasmed},
    {"st_sigma_s", u_ss},
    {"st_sigma_a", u_sa},
    {"st_phase_kind", u_pk},
    {"st_phase_g", u_pg},
    {"st_light_type", u_lt},
    {"st_light_dir", u_ld},
    {"st_light_shape", u_lshape},
};

void st_world_apply_uniforms(st_world *w, st_shader *sh, const st_frame *f) {
    for (size_t i = 0; i < sizeof builtin_uniforms / sizeof builtin_uniforms[0]; i++) {
        GLint l = st_shader_loc(sh, builtin_uniforms[i].name);
        if (l >= 0) builtin_uniforms[i].set(w, sh, l, f);
    }
    st_medium_gpu_uniforms(&w->medium, sh); /* hook: medium */
    for (int m = 0; m < w->num_mods; m++) {
        for (int i = 0; i < w->mods[m]->num_uniforms; i++) {
            const st_uniform *u = &w->mods[m]->uniforms[i];
            GLint l = st_shader_loc(sh, u->name);
            if (l >= 0) u->set(w->mods[m]->self, sh, l, f);
        }
    }
}

// ---- helpers ----------------------------------------------------------------

// The one tokenizer for comma-separated name lists ("a, b,c?"): copies the
// next name into out (spaces trimmed, at most ST_NAME_MAX - 1 bytes), sets
// *optional for a trailing '?' (which is dropped), and returns where to go on,
// or NULL at the end of the list.
static const char *next_name(const char *p, char out[ST_NAME_MAX], bool *optional) {
    while (p && (*p == ' ' || *p == ','))
        p++;
    if (!p || !*p) return NULL;
    const char *e = p;
    while (*e && *e != ',')
        e++;
    const char *t = e;
    while (t > p && t[-1] == ' ')
        t--;
    bool opt = t > p && t[-1] == '?';
    if (opt) t--;
    size_t n = (size_t)(t - p) < ST_NAME_MAX ? (size_t)(t - p) : ST_NAME_MAX - 1;
    memcpy(out, p, n);
    out[n] = 0;
    if (optional) *optional = opt;
    return e;
}

// Is `name` one of the (non-optional or optional) names in `list`?
static bool list_has(const char *list, const char *name) {
    char tok[ST_NAME_MAX];
    for (const char *p = list; (p = next_name(p, tok, NULL));)
        if (!strcmp(tok, name)) return true;
    return false;
}

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
    for (const char *p = list; (p = next_name(p, tok, NULL));) {
        if (!tok[0]) continue;
        int id = res_id(w, tok);
        if (id < 0)
            return st_fail(err, ST_ERR_RUNTIME, "more than %d resource names in the passes",
                           MAX_RESOURCES);
        out->bits[id / 64] |= 1ull << (id % 64);
    }
    return true;
}

static bool res_meet(const st_resset *a, const st_resset *b) {
    for (int i = 0; i < MAX_RESOURCES / 64; i++)
        if (a->bits[i] & b->bits[i]) return true;
    return false;
}

static void res_add(st_resset *a, const st_resset *b) {
    for (int i = 0; i < MAX_RESOURCES / 64; i++)
        a->bits[i] |= b->bits[i];
}

enum { RES_HDR = 0 }; // interned first by build_slots

static st_pass_stats *stats_for(st_world *w, const char *module, const char *pass) {
    for (int i = 0; i < w->num_stats; i++)
        if (!strcmp(w->stats[i].module, module) && !strcmp(w->stats[i].pass, pass))
            return &w->stats[i];
    if (w->num_stats == w->cap_stats) {
        int cap = w->cap_stats ? w->cap_stats * 2 : 16;
        st_pass_stats *n = realloc(w->stats, (size_t)cap * sizeof *n);
        if (!n) return NULL;
        w->stats = n;
        w->cap_stats = cap;
    }
    st_pass_stats *s = &w->stats[w->num_stats++];
    memset(s, 0, sizeof *s);
    snprintf(s->module, sizeof s->module, "%s", module);
    snprintf(s->pass, sizeof s->pass, "%s", pass);
    return s;
}

// ---- frame graph --------------------------------------------------------

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
    const char *mname = mi ? mi->p->name : "world";
    char pname[ST_NAME_MAX];
    snprintf(pname, sizeof pname, "%s", s->info.name);
    // Passes of one module sharing a name (one per light) are numbered.
    if (mi) {
        int total = 0, ordinal = 0, n = mi->p->num_passes(mi->self);
        for (int k = 0; k < n; k++) {
            const st_pass_info *o = mi->p->pass_info(mi->self, k);
            if (!o || !o->name || strcmp(o->name, s->info.name)) continue;
            if (k < pass) ordinal++;
            total++;
        }
        if (total > 1) snprintf(pname, sizeof pname, "%s[%d]", s->info.name, ordinal);
    }
    st_pass_stats *ps = stats_for(w, mname, pname);
    if (!ps) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    s->stats = (int)(ps - w->stats);
    // Timestamp pairs rather than GL_TIME_ELAPSED: llvmpipe reports a bogus
    // first elapsed time.
    if (w->opts.timing) glCreateQueries(GL_TIMESTAMP, 2, s->query);
    w->num_slots++;
    return true;
}

static void free_slots(st_world *w) {
    for (int i = 0; i < w->num_slots; i++)
        if (w->slots[i].query[0]) glDeleteQueries(2, w->slots[i].query);
    w->num_slots = 0;
}

// Rebuilds the pass list: pre-passes in module order, the regular pass,
// post passes in module order. Pending changes of surviving passes carry over.
static bool build_slots(st_world *w, st_err *err) {
    // Slots are matched by instance serial (0: the regular pass), never by
    // pointer: an unloaded instance's address may be reused by a new one.
    unsigned keep[MAX_SLOTS], keep_serial[MAX_SLOTS];
    int keep_pass[MAX_SLOTS], nkeep = w->num_slots;
    for (int i = 0; i < nkeep; i++) {
        keep[i] = w->slots[i].pending;
        keep_serial[i] = w->slots[i].serial;
        keep_pass[i] = w->slots[i].pass;
    }
    free_slots(w);
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
            int n = mi->p->num_passes(mi->self);
            for (int k = 0; k < n; k++) {
                const st_pass_info *info = mi->p->pass_info(mi->self, k);
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

static void make_frame(st_world *w, st_frame *f) {
    memset(f, 0, sizeof *f);
    f->world = w;
    f->scene = w->scene;
    f->index = w->frame;
    f->width = w->cam.width;
    f->height = w->cam.height;
    f->view = w->cam.view;
    f->proj = w->cam.proj;
    f->view_proj = w->cam.view_proj;
    f->inv_view_proj = w->cam.inv_view_proj;
    if (w->opts.filter == ST_FILTER_BOX) {
        f->proj = w->jit_proj;
        f->view_proj = w->jit_vp;
        f->inv_view_proj = w->jit_ivp;
    }
    f->cam_pos = w->cam.position;
    f->fov_y = w->cam.fov_y;
    f->near_z = w->cam.near_z;
    f->far_z = w->cam.far_z;
    f->gbuffer = w->cam.scene.color[1];
    f->albedo = w->cam.scene.color[2];
    f->depth = w->cam.scene.depth;
    f->hdr_in = w->cam.current;
}

static bool regular_pass(st_world *w, st_frame *f, st_err *err) {
    st_target_bind(&w->cam.scene);
    const float zero[4] = {0, 0, 0, 0}, nogeo[4] = {0, 0, 0, -1};
    const float *bg = w->scene->background; // where no geometry is drawn (black by default)
    glClearBufferfv(GL_COLOR, 0, (const float[]){bg[0], bg[1], bg[2], 0});
    glClearBufferfv(GL_COLOR, 1, nogeo);
    glClearBufferfv(GL_COLOR, 2, zero);
    glClearBufferfv(GL_DEPTH, 0, (const float[]){1.0f});
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    st_shader_use(w->regular);
    st_world_apply_uniforms(w, w->regular, f);
    st_world_draw(w, w->regular);
    // With a medium the background is dimmed per pixel (far / cos), which a
    // clear colour cannot do: drawn at depth 1 where no geometry is.
    if (w->background && w->scene->medium.present) {
        glDepthFunc(GL_EQUAL);
        glDepthMask(GL_FALSE);
        glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glColorMaski(2, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        st_shader_use(w->background);
        st_world_apply_uniforms(w, w->background, f);
        st_shader_set_vec3(w->background, "st_background_radiance", bg);
        st_draw_fullscreen();
        glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glColorMaski(2, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthMask(GL_TRUE);
        glDepthFunc(GL_LESS);
    }
    glDisable(GL_DEPTH_TEST);
    w->cam.current = w->cam.scene.color[0];
    w->cam.post_out = 0;
    return st_gl_check("regular pass", err);
}

// ---- world-owned targets ------------------------------------------------------

bool st_world_declare_target(st_world *w, const char *name, const st_target_desc *d, st_err *err) {
    return st_targets_declare(&w->targets, name, d, err);
}

const st_target *st_world_get_target(st_world *w, const char *name, st_err *err) {
    int i = st_targets_find(&w->targets, name);
    if (i < 0) {
        st_fail(err, ST_ERR_RUNTIME, "target '%s' was not declared", name);
        return NULL;
    }
    if (!st_targets_ensure(&w->targets, i, w->cam.width, w->cam.height, err)) return NULL;
    return &w->targets.t[i].t;
}

const st_target *st_world_alloc_target(st_world *w, const char *name, const st_target_desc *d,
                                       st_err *err) {
    return st_world_declare_target(w, name, d, err) ? st_world_get_target(w, name, err) : NULL;
}

const st_target *st_world_target(st_world *w, const char *name) {
    st_err ignore = {0};
    return st_world_get_target(w, name, &ignore);
}

bool st_world_track(st_world *w, const char *name, GLenum identifier, GLuint obj, st_err *err) {
    return st_targets_track(&w->targets, name, identifier, obj, err);
}

void st_world_untrack(st_world *w, const char *name) {
    st_targets_untrack(&w->targets, name);
}

static int add_row(st_mem_entry *out, int max, int n, const st_mem_entry *e) {
    if (out && n < max) out[n] = *e;
    return n + 1;
}

static int module_rows(st_world *w, const char *owner, st_mem_entry *out, int max, int n) {
    st_targets *s = &w->targets;
    st_mem_entry e;
    for (int i = 0; i < s->n; i++) {
        st_targets_entry(s->t[i].name, &s->t[i].t, &e);
        if (strcmp(e.owner, owner)) continue;
        if (!s->t[i].t.color[0]) // declared, not used yet
            snprintf(e.format, sizeof e.format, "%s", st_format_name(s->t[i].desc.format));
        n = add_row(out, max, n, &e);
    }
    for (int i = 0; i < s->nk; i++) {
        memset(&e, 0, sizeof e);
        snprintf(e.name, sizeof e.name, "%s", s->k[i].name);
        snprintf(e.owner, sizeof e.owner, "%.*s", (int)strcspn(e.name, "."), e.name);
        if (strcmp(e.owner, owner)) continue;
        snprintf(e.format, sizeof e.format, "-");
        e.kind = s->k[i].identifier == GL_BUFFER ? "buffer" : "buffer texture";
        e.bytes = s->k[i].bytes;
        n = add_row(out, max, n, &e);
    }
    return n;
}

int st_world_memory(st_world *w, st_mem_entry *out, int max) {
    int n = 0;
    st_mem_entry e;
    const st_target *cam[5] = {&w->cam.scene, &w->cam.post[0], &w->cam.post[1], &w->cam.accum[0],
                               &w->cam.accum[1]};
    const char *names[5] = {"camera.scene", "camera.post0", "camera.post1", "camera.accum0",
                            "camera.accum1"};
    for (int i = 0; i < (w->cam.accum[0].fbo ? 5 : 3); i++) {
        st_targets_entry(names[i], cam[i], &e);
        n = add_row(out, max, n, &e);
    }
    const st_buffer *geo[2] = {&w->type.vbo, &w->type.ibo};
    const char *gnames[2] = {"world.vertices", "world.indices"};
    for (int i = 0; i < 2; i++) {
        memset(&e, 0, sizeof e);
        snprintf(e.name, sizeof e.name, "%s", gnames[i]);
        snprintf(e.owner, sizeof e.owner, "world");
        snprintf(e.format, sizeof e.format, "-");
        e.kind = "buffer";
        e.bytes = geo[i]->size;
        n = add_row(out, max, n, &e);
    }
    for (int m = 0; m < w->num_mods; m++)
        n = module_rows(w, w->mods[m]->p->name, out, max, n);
    return n;
}

size_t st_world_memory_bytes(st_world *w) {
    st_mem_entry rows[ST_MAX_TARGETS + ST_MAX_TRACKED + 8];
    int n = st_world_memory(w, rows, (int)(sizeof rows / sizeof rows[0]));
    size_t sum = 0;
    for (int i = 0; i < n; i++)
        sum += rows[i].bytes;
    return sum;
}

// ---- the box pixel filter -------------------------------------------------------

static double radical_inverse(uint32_t k, uint32_t base) {
    double inv = 1.0 / base, f = inv, r = 0;
    for (; k; k /= base, f *= inv)
        r += f * (k % base);
    return r;
}

void st_jitter_offset(uint32_t k, float out[2]) {
    double x = radical_inverse(k, 2) + 0.5, y = radical_inverse(k, 3) + 0.5;
    out[0] = (float)(x - floor(x) - 0.5);
    out[1] = (float)(y - floor(y) - 0.5);
}

// The camera's matrices for a sample `jitter` pixels right of and below the
// pixel centre: the image shifts the other way in NDC.
static void jitter_matrices(st_world *w) {
    mat4 t = GLM_MAT4_IDENTITY_INIT, proj, view, p, vp, inv;
    t[3][0] = -2.0f * w->jitter[0] / (float)w->cam.width;
    t[3][1] = 2.0f * w->jitter[1] / (float)w->cam.height;
    memcpy(proj, w->cam.proj, sizeof proj);
    memcpy(view, w->cam.view, sizeof view);
    glm_mat4_mul(t, proj, p);
    glm_mat4_mul(p, view, vp);
    glm_mat4_inv(vp, inv);
    memcpy(w->jit_proj, p, sizeof w->jit_proj);
    memcpy(w->jit_vp, vp, sizeof w->jit_vp);
    memcpy(w->jit_ivp, inv, sizeof w->jit_ivp);
}

// Whether every progressive module has converged (true without any): until
// then each frame's image differs, so it replaces the accumulated one.
static bool modules_settled(const st_world *w) {
    for (int i = 0; i < w->num_mods; i++) {
        st_progress p = {0};
        const st_plugin *pl = w->mods[i]->p;
        if (pl->progress && pl->progress(w->mods[i]->self, &p) && !p.converged) return false;
    }
    return true;
}

// The convergence test: the relative standard error of the mean image,
// E = sqrt(mean over pixels of (s_p^2 / n) / (m_p^2 + M^2)), with m_p and
// s_p^2 the mean and sample variance of pixel p's luminance over n frames and
// M the image's mean luminance: atlas_gi's rule for its gather (the RMS
// standard error relative to the mean), with each pixel relative to its own
// value where that is brighter, so a few very bright pixels (a light's hot
// spot) do not hold up the whole image, and dark ones count against M.
static bool accum_error(st_world *w, const st_target *t, uint32_t n, st_err *err) {
    size_t px = (size_t)t->width * t->height;
    if (!w->acc_read && !(w->acc_read = malloc(px * 4 * sizeof(float))))
        return st_fail(err, ST_ERR_RUNTIME, "out of memory reading back %dx%d", t->width,
                       t->height);
    glGetTextureImage(t->color[0], 0, GL_RGBA, GL_FLOAT, (GLsizei)(px * 4 * sizeof(float)),
                      w->acc_read);
    double sum_m = 0, sum_e = 0;
    for (size_t k = 0; k < px; k++) {
        const float *a = w->acc_read + 4 * k;
        sum_m += ((double)a[0] + a[1] + a[2]) / 3.0 / n;
    }
    double M2 = (sum_m / px) * (sum_m / px);
    for (size_t k = 0; k < px; k++) {
        const float *a = w->acc_read + 4 * k;
        double m = ((double)a[0] + a[1] + a[2]) / 3.0 / n;
        double var_mean = fmax(0.0, (a[3] - n * m * m) / (n - 1)) / n;
        sum_e += var_mean / (m * m + M2);
    }
    w->acc_err = M2 > 0 ? sqrt(sum_e / px) : 0;
    if (!isfinite(w->acc_err)) w->acc_err = INFINITY;
    return st_gl_check("accumulation read back", err);
}

// Adds the frame just rendered to the running sums; the mean becomes the
// camera's current image.
static bool accumulate(st_world *w, st_err *err) {
    st_camera *c = &w->cam;
    double t0 = st_now_ms();
    int next = w->acc_cur ^ 1;
    st_target_bind(&c->accum[next]);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    st_shader_use(w->accumulate);
    st_shader_texture(w->accumulate, "st_hdr_in", GL_TEXTURE_2D, c->current);
    st_shader_texture(w->accumulate, "st_acc_prev", GL_TEXTURE_2D, c->accum[w->acc_cur].color[0]);
    st_shader_set_int(w->accumulate, "st_acc_first", w->acc_n == 0);
    st_shader_set_float(w->accumulate, "st_acc_n", (float)(w->acc_n + 1));
    st_draw_fullscreen();
    w->acc_cur = next;
    w->acc_n++;
    c->current = c->accum[next].color[1];
    if (!st_gl_check("accumulate", err)) return false;
    w->acc_err = INFINITY;
    if (!modules_settled(w)) {
        w->acc_n = 0; // the next frame starts again (at the centre)
    } else {
        uint32_t cap = w->opts.filter_max_frames > 0 ? (uint32_t)w->opts.filter_max_frames
                                                     : ST_FILTER_MAX_FRAMES;
        double tol = w->opts.filter_tolerance != 0 ? w->opts.filter_tolerance : ST_FILTER_TOLERANCE;
        if (w->acc_n >= 4 || (w->acc_n >= cap && w->acc_n >= 2))
            if (!accum_error(w, &c->accum[next], w->acc_n, err)) return false;
        if (w->acc_n == 1 && cap == 1) w->acc_err = 0;
        w->acc_done = w->acc_n >= cap || (w->acc_n >= 4 && w->acc_err <= tol);
    }
    st_pass_stats *ps = &w->stats[w->acc_stats];
    ps->runs++;
    ps->ran_last_frame = true;
    if (ps->num_samples < ST_STATS_MAX_SAMPLES) {
        ps->cpu_ms[ps->num_samples] = (float)(st_now_ms() - t0);
        ps->gpu_ms[ps->num_samples] = -1;
        ps->num_samples++;
    }
    return true;
}

static bool run_slot(st_world *w, st_slot *s, st_frame *f, st_err *err) {
    if (!s->mod) return regular_pass(w, f, err);
    st_module_inst *mi = s->mod;
    const st_plugin *p = mi->p;
    bool to_hdr = s->info.stage == ST_STAGE_POST && (s->writes.bits[0] & (1ull << RES_HDR));
    GLuint fbo = p->rendertarget ? p->rendertarget(mi->self, s->pass) : 0;
    f->hdr_in = w->cam.current;
    if (fbo) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    } else if (to_hdr) {
        st_target_bind(&w->cam.post[w->cam.post_out]);
    } else {
        // The world-owned target this pass writes, if any.
        for (int i = 0; i < w->targets.n; i++) { // (1D lookup tables are not drawn into)
            if (w->targets.t[i].desc.type == GL_TEXTURE_1D ||
                !list_has(s->info.writes, w->targets.t[i].name))
                continue;
            if (!st_targets_ensure(&w->targets, i, w->cam.width, w->cam.height, err)) return false;
            st_target_bind(&w->targets.t[i].t);
            break;
        }
    }
    if (to_hdr) glViewport(0, 0, w->cam.width, w->cam.height);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    if (s->info.flags & ST_PASS_SCENE) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
    st_shader *sh = p->shader ? p->shader(mi->self, s->pass) : NULL;
    if (sh) {
        st_shader_use(sh);
        st_world_apply_uniforms(w, sh, f);
        st_shader_texture(sh, "st_hdr_in", GL_TEXTURE_2D, f->hdr_in);
        st_shader_texture(sh, "st_gbuffer", GL_TEXTURE_2D, f->gbuffer);
        st_shader_texture(sh, "st_albedo_tex", GL_TEXTURE_2D, f->albedo);
    }
    if (p->on_pass && !p->on_pass(mi->self, s->pass, f, err)) {
        st_err_prefix(err, "module '%s', pass '%s': ", p->name, s->info.name);
        return false;
    }
    if (sh && (s->info.flags & ST_PASS_SCENE)) st_world_draw(w, sh);
    if (sh && (s->info.flags & ST_PASS_FULLSCREEN)) st_draw_fullscreen();
    if (p->after_pass) p->after_pass(mi->self, s->pass, f);
    glDisable(GL_DEPTH_TEST);
    if (to_hdr) {
        w->cam.current = w->cam.post[w->cam.post_out].color[0];
        w->cam.post_out ^= 1;
    }
    char what[160];
    snprintf(what, sizeof what, "module '%s', pass '%s'", p->name, s->info.name);
    return st_gl_check(what, err);
}

bool st_world_frame(st_world *w, st_err *err) {
    if (w->opts.filter == ST_FILTER_BOX) {
        unsigned outside = w->changes;
        for (int m = 0; m < w->num_mods; m++)
            if (w->mods[m]->params_dirty) outside |= ST_CHANGE_PARAMS;
        if (outside) w->acc_n = 0, w->acc_done = false, w->acc_err = INFINITY;
        if (w->acc_done) {
            // Converged and nothing changed: the mean stays, no pass runs.
            for (int i = 0; i < w->num_stats; i++)
                w->stats[i].ran_last_frame = false;
            for (int i = 0; i < w->num_slots; i++)
                w->stats[w->slots[i].stats].skipped++;
            w->frame++;
            return true;
        }
        // Only what depends on the camera redoes a jittered frame.
        float j[2];
        st_jitter_offset(w->acc_n, j);
        if (j[0] != w->jitter[0] || j[1] != w->jitter[1]) w->changes |= ST_CHANGE_CAMERA;
        memcpy(w->jitter, j, sizeof j);
        jitter_matrices(w);
    }
    // Distribute this frame's changes to every pass.
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        s->pending |= w->changes;
        if (s->mod && s->mod->params_dirty) s->pending |= ST_CHANGE_PARAMS;
    }
    for (int m = 0; m < w->num_mods; m++)
        w->mods[m]->params_dirty = false;
    w->changes = 0;

    st_frame f;
    make_frame(w, &f);
    // Forward: which passes want to run; a pass that will rewrite a resource
    // marks its readers' inputs as changed.
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        const st_plugin *p = s->mod ? s->mod->p : NULL;
        f.changes = s->pending;
        s->needed = !p || !p->needed || p->needed(s->mod->self, s->pass, &f);
        if (!s->needed) continue;
        for (int j = i + 1; j < w->num_slots; j++)
            if (res_meet(&s->writes, &w->slots[j].reads)) w->slots[j].pending |= ST_CHANGE_INPUTS;
    }
    // Backward: the final image is the root; a pass is live if a later live
    // pass reads what it writes. A skipped pass reads nothing this frame.
    st_resset live = {{1ull << RES_HDR}};
    for (int i = w->num_slots - 1; i >= 0; i--) {
        st_slot *s = &w->slots[i];
        s->live = (s->info.flags & ST_PASS_SIDE_EFFECT) || res_meet(&s->writes, &live);
        if (s->live && s->needed) res_add(&live, &s->reads);
    }
    for (int i = 0; i < w->num_slots; i++) {
        st_slot *s = &w->slots[i];
        st_pass_stats *ps = &w->stats[s->stats];
        ps->ran_last_frame = false;
        ps->culled_last_frame = !s->live;
        if (!s->live) {
            ps->culled++;
            continue;
        }
        if (!s->needed) {
            ps->skipped++;
            continue;
        }
        f.changes = s->pending;
        double t0 = st_now_ms();
        if (s->query[0]) glQueryCounter(s->query[0], GL_TIMESTAMP);
        // One debug group per pass, named as in --stats, so GPU captures
        // (RenderDoc, apitrace) read like the stats table.
        char group[2 * ST_NAME_MAX + 2];
        snprintf(group, sizeof group, "%s/%s", ps->module, ps->pass);
        glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, (GLuint)i, -1, group);
        bool ok = run_slot(w, s, &f, err);
        glPopDebugGroup();
        if (s->query[1]) glQueryCounter(s->query[1], GL_TIMESTAMP);
        if (!ok) return false;
        double t1 = st_now_ms();
        s->pending = 0;
        ps->runs++;
        ps->ran_last_frame = true;
        if (ps->num_samples < ST_STATS_MAX_SAMPLES) {
            ps->cpu_ms[ps->num_samples] = (float)(t1 - t0);
            ps->gpu_ms[ps->num_samples] = -1;
            ps->num_samples++;
        }
    }
    if (w->opts.timing) {
        for (int i = 0; i < w->num_slots; i++) {
            st_slot *s = &w->slots[i];
            st_pass_stats *ps = &w->stats[s->stats];
            if (!s->query[0] || !ps->ran_last_frame) continue;
            GLuint64 t0 = 0, t1 = 0;
            glGetQueryObjectui64v(s->query[0], GL_QUERY_RESULT, &t0);
            glGetQueryObjectui64v(s->query[1], GL_QUERY_RESULT, &t1);
            ps->gpu_ms[ps->num_samples - 1] = (float)((t1 > t0 ? t1 - t0 : 0) * 1e-6);
        }
    }
    if (w->opts.filter == ST_FILTER_BOX && !accumulate(w, err)) return false;
    w->frame++;
    return st_gl_check("frame", err);
}

bool st_world_read(st_world *w, st_image *out, st_err *err) {
    int W_ = w->cam.width, H = w->cam.height;
    st_target tmp = {0};
    // The latest image may be a post target or the scene target's colour 0.
    const st_target *src = &w->cam.scene;
    int index = 0;
    for (int i = 0; i < 2; i++) {
        if (w->cam.post[i].color[0] == w->cam.current) src = &w->cam.post[i];
        if (w->cam.accum[i].color[1] && w->cam.accum[i].color[1] == w->cam.current)
            src = &w->cam.accum[i], index = 1;
    }
    float *rgba = malloc((size_t)W_ * H * 4 * sizeof(float));
    if (!rgba) return st_fail(err, ST_ERR_RUNTIME, "out of memory reading %dx%d", W_, H);
    bool ok = st_target_read(src, index, rgba, err);
    (void)tmp;
    if (ok) ok = st_image_alloc(out, W_, H, 3, err);
    if (ok) {
        for (size_t k = 0; k < (size_t)W_ * H; k++)
            for (int c = 0; c < 3; c++)
                out->data[3 * k + c] = rgba[4 * k + c];
    }
    free(rgba);
    return ok;
}

void st_world_draw(st_world *w, st_shader *sh) {
    st_model_type_draw(&w->type, w->models, w->num_models, sh);
}

// ---- modules ----------------------------------------------------------------

static int find_module(const st_world *w, const char *name) {
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

static void unload(st_world *w, int m) {
    st_module_inst *mi = w->mods[m];
    if (mi->self) mi->p->destroy(mi->self);
    st_targets_free(&w->targets, mi->p->name);
    st_plugin_close(mi->lib);
    free(mi);
    // Only the pointers move; the other instances stay where they are.
    memmove(&w->mods[m], &w->mods[m + 1], (size_t)(w->num_mods - m - 1) * sizeof w->mods[0]);
    w->num_mods--;
}

static bool build_regular(st_world *w, st_err *err);

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
static bool load(st_world *w, const char *name, st_err *err) {
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

// Orders modules so each comes after the providers of what it requires
// (a requirement "name?" is optional: it only orders).
static bool resolve(st_world *w, st_err *err) {
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
                 ok && (r = next_name(r, tmp, &optional));) {
                if (!tmp[0]) continue;
                // "name?" is optional: after its provider when one is loaded.
                bool found = false, any = false;
                for (int j = 0; j < w->num_mods; j++) {
                    if (j == i || !list_has(w->mods[j]->p->provides, tmp)) continue;
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

static bool instantiate(st_world *w, int m, st_err *err) {
    st_module_inst *mi = w->mods[m];
    if (mi->self) return true;
    mi->self = mi->p->create(w, mi->params, err);
    if (!mi->self) {
        st_err_prefix(err, "module '%s': ", mi->p->name);
        return false;
    }
    mi->num_uniforms = mi->p->uniforms ? mi->p->uniforms(mi->self, &mi->uniforms) : 0;
    mi->params_dirty = true;
    return true;
}

// ---- creation ----------------------------------------------------------------

static void light_defines(st_world *w) {
    unsigned types = 0;
    for (int i = 0; i < w->scene->num_lights; i++)
        types |= 1u << w->scene->lights[i].type;
    snprintf(w->light_defines, sizeof w->light_defines, "ST_MAX_LIGHTS %d\nST_LIGHT_TYPES %u\n",
             ST_MAX_LIGHTS, types);
    st_medium_gpu_defines(w->scene, w->light_defines, sizeof w->light_defines); /* hook: medium */
}

static bool build_regular(st_world *w, st_err *err) {
    char defines[1024];
    int n = snprintf(defines, sizeof defines, "%s", w->light_defines);
    for (int m = 0; m < w->num_mods; m++)
        if (w->mods[m]->p->regular_include)
            n += snprintf(defines + n, sizeof defines - (size_t)n, "#include \"%s\"\n",
                          w->mods[m]->p->regular_include);
    st_shader *sh = st_shader_load("common/regular.vert", "common/regular.frag", defines, err);
    if (!sh) return false;
    st_shader *bg = NULL;
    if (w->scene->has_background) {
        bg = st_shader_load("common/fullscreen.vert", "common/background.frag", w->light_defines,
                            err);
        if (!bg) {
            st_shader_destroy(sh);
            return false;
        }
    }
    st_shader_destroy(w->regular);
    st_shader_destroy(w->background);
    w->regular = sh;
    w->background = bg;
    return true;
}

static bool create_targets(st_world *w, st_err *err) {
    st_camera *c = &w->cam;
    st_target_destroy(&c->scene);
    st_target_destroy(&c->post[0]);
    st_target_destroy(&c->post[1]);
    st_target_destroy(&c->accum[0]);
    st_target_destroy(&c->accum[1]);
    w->acc_n = 0, w->acc_done = false, w->acc_err = INFINITY;
    free(w->acc_read);
    w->acc_read = NULL;
    for (int i = 0; w->opts.filter == ST_FILTER_BOX && i < 2; i++) {
        if (!st_target_create(&c->accum[i], c->width, c->height, 2, GL_RGBA32F, false, err))
            return false;
        char name[32];
        snprintf(name, sizeof name, "camera.accum%d", i);
        glObjectLabel(GL_FRAMEBUFFER, c->accum[i].fbo, -1, name);
    }
    if (!st_target_create(&c->scene, c->width, c->height, 3, GL_RGBA32F, true, err) ||
        !st_target_create(&c->post[0], c->width, c->height, 1, GL_RGBA32F, false, err) ||
        !st_target_create(&c->post[1], c->width, c->height, 1, GL_RGBA32F, false, err))
        return false;
    // The resource names of the pass list, for debuggers.
    glObjectLabel(GL_FRAMEBUFFER, c->scene.fbo, -1, "camera.scene");
    glObjectLabel(GL_TEXTURE, c->scene.color[0], -1, "hdr");
    glObjectLabel(GL_TEXTURE, c->scene.color[1], -1, "gbuffer");
    glObjectLabel(GL_TEXTURE, c->scene.color[2], -1, "albedo");
    glObjectLabel(GL_TEXTURE, c->scene.depth, -1, "depth");
    for (int i = 0; i < 2; i++) {
        char name[32];
        snprintf(name, sizeof name, "camera.post%d", i);
        glObjectLabel(GL_FRAMEBUFFER, c->post[i].fbo, -1, name);
        snprintf(name, sizeof name, "hdr (post %d)", i);
        glObjectLabel(GL_TEXTURE, c->post[i].color[0], -1, name);
    }
    return st_gl_check("camera targets", err);
}

st_world *st_world_create(const st_scene *scene, const st_world_opts *opts, st_err *err) {
    st_world *w = calloc(1, sizeof *w);
    if (!w) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    w->scene = scene;
    light_defines(w);
    if (opts) w->opts = *opts;
    if (scene->num_lights > ST_MAX_LIGHTS) {
        st_fail(err, ST_ERR_INPUT, "%s: lights: %d lights, at most %d are supported", scene->path,
                scene->num_lights, ST_MAX_LIGHTS);
        free(w);
        return NULL;
    }
    if (!st_medium_gpu_create(&w->medium, scene, err)) { /* hook: medium */
        free(w);
        return NULL;
    }
    w->num_lights = scene->num_lights;
    for (int i = 0; i < scene->num_lights; i++) {
        memcpy(w->light_pos[i], scene->lights[i].position, sizeof w->light_pos[i]);
        memcpy(w->light_int[i], scene->lights[i].intensity, sizeof w->light_int[i]);
        const st_light_desc *l = &scene->lights[i];
        w->light_type[i] = (int)l->type;
        memcpy(w->light_dir[i], l->direction, sizeof w->light_dir[i]);
        if (l->type == ST_LIGHT_SPOT) { // st_spot_falloff as scale and offset in cos
            double co = cos(l->outer_angle), scale = 1.0 / fmax(0.001, cos(l->inner_angle) - co);
            w->light_shape[i][0] = (float)scale, w->light_shape[i][1] = (float)(-co * scale);
        }
        if (l->type == ST_LIGHT_DIRECTIONAL) // no geometry: -inf, kept finite for GL
            w->light_shape[i][2] = (float)fmax(st_directional_entry(scene, l->direction), -1e30);
    }
    st_camera *c = &w->cam;
    memcpy(c->position, scene->camera.position, sizeof c->position);
    memcpy(c->target, scene->camera.target, sizeof c->target);
    memcpy(c->up, scene->camera.up, sizeof c->up);
    c->fov_y = scene->camera.fov_y;
    c->near_z = scene->camera.near_z;
    c->far_z = scene->camera.far_z;
    c->width = w->opts.width > 0 ? w->opts.width : scene->width;
    c->height = w->opts.height > 0 ? w->opts.height : scene->height;
    st_camera_update(c);
    w->changes = ST_CHANGE_ALL;

    w->num_models = scene->num_meshes;
    w->models = calloc(w->num_models ? (size_t)w->num_models : 1, sizeof *w->models);
    bool ok = w->models && st_model_type_build(&w->type, "lit", scene->meshes, scene->num_meshes,
                                               NULL, w->models, err);
    if (!w->models) st_fail(err, ST_ERR_RUNTIME, "out of memory");
    if (ok) { // named as in st_world_memory
        glObjectLabel(GL_BUFFER, w->type.vbo.id, -1, "world.vertices");
        glObjectLabel(GL_BUFFER, w->type.ibo.id, -1, "world.indices");
    }
    ok = ok && create_targets(w, err);
    for (int i = 0; ok && i < scene->num_modules; i++)
        ok = load(w, scene->modules[i].name, err);
    ok = ok && resolve(w, err);
    for (int m = 0; ok && m < w->num_mods; m++)
        ok = instantiate(w, m, err);
    ok = ok && build_regular(w, err) && build_slots(w, err);
    if (ok && w->opts.filter == ST_FILTER_BOX) {
        st_pass_stats *ps = stats_for(w, "world", "accumulate");
        w->acc_stats = ps ? (int)(ps - w->stats) : 0;
        if (!ps) ok = st_fail(err, ST_ERR_RUNTIME, "out of memory");
        w->accumulate =
            ok ? st_shader_load("common/fullscreen.vert", "common/accumulate.frag", NULL, err)
               : NULL;
        ok = ok && w->accumulate;
    }
    if (!ok) {
        st_world_destroy(w);
        return NULL;
    }
    w->cam.current = w->cam.scene.color[0];
    return w;
}

void st_world_destroy(st_world *w) {
    if (!w) return;
    // Teardown order: instances, then each plugin's cleanup, then dlclose.
    for (int m = 0; m < w->num_mods; m++)
        if (w->mods[m]->self) w->mods[m]->p->destroy(w->mods[m]->self), w->mods[m]->self = NULL;
    while (w->num_mods)
        unload(w, w->num_mods - 1);
    st_targets_free(&w->targets, NULL);
    free_slots(w);
    st_shader_destroy(w->regular);
    st_shader_destroy(w->background);
    st_model_type_destroy(&w->type);
    st_target_destroy(&w->cam.scene);
    st_target_destroy(&w->cam.post[0]);
    st_target_destroy(&w->cam.post[1]);
    st_target_destroy(&w->cam.accum[0]);
    st_target_destroy(&w->cam.accum[1]);
    st_shader_destroy(w->accumulate);
    st_medium_gpu_destroy(&w->medium); /* hook: medium */
    free(w->acc_read);
    free(w->models);
    free(w->stats);
    free(w);
}

// ---- accessors and interactive changes ----------------------------------

const st_scene *st_world_scene(const st_world *w) {
    return w->scene;
}
st_camera *st_world_camera(st_world *w) {
    return &w->cam;
}

const char *st_world_light_defines(const st_world *w) {
    return w->light_defines;
}

void st_world_invalidate(st_world *w, unsigned changes) {
    w->changes |= changes;
}

void st_world_set_camera(st_world *w, const float pos[3], const float target[3],
                         const float up[3]) {
    memcpy(w->cam.position, pos, sizeof w->cam.position);
    memcpy(w->cam.target, target, sizeof w->cam.target);
    memcpy(w->cam.up, up, sizeof w->cam.up);
    st_camera_update(&w->cam);
    w->changes |= ST_CHANGE_CAMERA;
}

bool st_world_resize(st_world *w, int width, int height, st_err *err) {
    if (width == w->cam.width && height == w->cam.height) return true;
    if (width < 1 || height < 1) return st_fail(err, ST_ERR_INPUT, "bad size %dx%d", width, height);
    w->cam.width = width;
    w->cam.height = height;
    st_camera_update(&w->cam);
    w->changes |= ST_CHANGE_SIZE | ST_CHANGE_CAMERA;
    if (!create_targets(w, err)) return false;
    w->cam.current = w->cam.scene.color[0];
    return true;
}

bool st_world_has_module(const st_world *w, const char *module) {
    return find_module(w, module) >= 0;
}

bool st_world_enable(st_world *w, const char *module, bool on, st_err *err) {
    int m = find_module(w, module);
    if (on == (m >= 0)) return true;
    if (on && !st_medium_gpu_check_module(w->scene, module, err)) return false; /* hook: medium */
    unsigned before = w->next_serial; // instances with a larger serial are this call's
    if (on) {
        if (!load(w, module, err)) return false;
        // Load what it requires first (turning on toth turns on shadow_map).
        const char *req = w->mods[w->num_mods - 1]->p->requires;
        char tmp[ST_NAME_MAX];
        bool optional;
        for (const char *r = req; (r = next_name(r, tmp, &optional));) {
            if (!tmp[0] || optional) continue; // optional requirements are not loaded
            bool have = false;
            for (int j = 0; j < w->num_mods; j++)
                have |= list_has(w->mods[j]->p->provides, tmp);
            if (!have && !load(w, tmp, err)) {
                for (int i = w->num_mods - 1; i >= 0; i--) // everything this call loaded
                    if (w->mods[i]->serial > before) unload(w, i);
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
                 j != m && (r = next_name(r, tmp, &optional));)
                if (tmp[0] && !optional && list_has(w->mods[m]->p->provides, tmp))
                    return st_fail(err, ST_ERR_INPUT, "module '%s' is required by '%s'", module,
                                   w->mods[j]->p->name);
        w->mods[m]->p->destroy(w->mods[m]->self);
        w->mods[m]->self = NULL;
        unload(w, m);
    }
    bool ok = resolve(w, err);
    for (int i = 0; ok && i < w->num_mods; i++)
        ok = instantiate(w, i, err);
    ok = ok && build_regular(w, err);
    if (!ok && on) {
        // A module (or its regular include) failed: unload what this call
        // loaded; the regular shader is only replaced on success.
        for (int i = w->num_mods - 1; i >= 0; i--) {
            if (w->mods[i]->serial > before) unload(w, i);
        }
    }
    // The pass list always follows the module list, also after a failure.
    st_err ignore = {0};
    if (!build_slots(w, ok ? err : &ignore)) ok = false;
    w->changes |= ST_CHANGE_CAMERA;
    return ok;
}

bool st_world_set_param(st_world *w, const char *module, const char *param, double value,
                        st_err *err) {
    int m = find_module(w, module);
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
    mi->params[k] = value;
    mi->params_dirty = true;
    if (mi->p->param_changed) mi->p->param_changed(mi->self, k);
    // A parameter may change a module's pass list (e.g. interleave on/off).
    return build_slots(w, err);
}

bool st_world_get_param(const st_world *w, const char *module, const char *param, double *value) {
    int m = find_module(w, module);
    if (m < 0) return false;
    int k = st_param_index(w->mods[m]->p, param);
    if (k < 0) return false;
    *value = w->mods[m]->params[k];
    return true;
}

bool st_world_set_light(st_world *w, int i, const float pos[3], const float intensity[3],
                        st_err *err) {
    if (i < 0 || i >= w->num_lights)
        return st_fail(err, ST_ERR_INPUT, "light %d: the scene has %d", i, w->num_lights);
    memcpy(w->light_pos[i], pos, sizeof w->light_pos[i]);
    memcpy(w->light_int[i], intensity, sizeof w->light_int[i]);
    // Modules (shadow_map) read lights from the scene the caller lent the
    // world; it is the caller's, so it follows the move too.
    st_light_desc *l = &((st_scene *)w->scene)->lights[i];
    memcpy(l->position, pos, sizeof l->position);
    memcpy(l->intensity, intensity, sizeof l->intensity);
    st_world_invalidate(w, ST_CHANGE_LIGHTS);
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
                 "%sfilter: box, %u frame(s) accumulated, relative standard error %.4g",
                 n ? "; " : "", w->acc_n, w->acc_err);
    }
    return any;
}

uint32_t st_world_accumulated(const st_world *w, bool *done) {
    if (done) *done = w->opts.filter == ST_FILTER_BOX && w->acc_done;
    return w->opts.filter == ST_FILTER_BOX ? w->acc_n : 0;
}

bool st_world_reload_shaders(st_world *w, st_err *err) {
    // Rebuilt for the current module list (a switch made while the file was
    // broken left the old program); the old one stays on failure.
    if (!build_regular(w, err)) return false;
    for (int m = 0; m < w->num_mods; m++) {
        st_module_inst *mi = w->mods[m];
        if (mi->p->reload && !mi->p->reload(mi->self, err)) {
            st_err_prefix(err, "module '%s': ", mi->p->name);
            return false;
        }
    }
    w->changes |= ST_CHANGE_CAMERA;
    return true;
}

int st_world_num_modules(const st_world *w) {
    return w->num_mods;
}
st_module_info st_world_module(const st_world *w, int i) {
    st_module_info mi = {w->mods[i]->p, (double *)w->mods[i]->params};
    return mi;
}

int st_world_num_pass_stats(const st_world *w) {
    return w->num_stats;
}
const st_pass_stats *st_world_pass_stats(const st_world *w, int i) {
    return &w->stats[i];
}
void st_world_reset_stats(st_world *w) {
    for (int i = 0; i < w->num_stats; i++) {
        st_pass_stats *s = &w->stats[i];
        s->runs = s->skipped = s->culled = 0;
        s->num_samples = 0;
    }
}

void st_world_reset_samples(st_world *w) {
    for (int i = 0; i < w->num_stats; i++)
        w->stats[i].num_samples = 0;
}

static int cmp_d(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double st_median_d(const double *v, int n) {
    if (n <= 0) return 0;
    double *t = malloc((size_t)n * sizeof *t);
    if (!t) return 0;
    memcpy(t, v, (size_t)n * sizeof *t);
    qsort(t, (size_t)n, sizeof *t, cmp_d);
    double m = n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
    free(t);
    return m;
}

double st_median_f(const float *v, int n) {
    if (n <= 0) return 0;
    double *d = malloc((size_t)n * sizeof *d);
    if (!d) return 0;
    for (int i = 0; i < n; i++)
        d[i] = v[i];
    double m = st_median_d(d, n);
    free(d);
    return m;
}
