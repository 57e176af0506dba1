// strahl (internal): the World's state, shared by the files that implement
// it (docs/architecture.md "Where the world lives" maps them):
//   st_world.c          creation, destruction, camera targets, accessors
//   st_world_modules.c  module load, `requires` ordering, switch, params, reload
//   st_world_regular.c  the regular pass's program
//   st_passes.c         declared passes: expansion, programs, targets
//   st_graph.c          resource interning, the pass list (slots), culling
//   st_frame.c          one frame: the regular pass, module passes, timing
//   st_filter.c         the box pixel filter: jitter and accumulation
//   st_uniforms.c       the built-in uniform table, binding a pass's program
//   st_world_targets.c  world-owned targets and tracked objects (wrappers)
//   st_world_stats.c    pass statistics and the GPU memory report
#ifndef ST_WORLD_STATE_H
#define ST_WORLD_STATE_H
#include "st_list.h"
#include "st_medium_gpu.h"
#include "st_targets.h"
#include "st_world.h"

#define MAX_MODULES 16
#define MAX_SLOTS 128
#define MAX_RESOURCES 128 // distinct resource names in one pass list

// A set of resources, by id (index into st_world.res).
typedef struct st_resset {
    uint64_t bits[MAX_RESOURCES / 64];
} st_resset;

// A declared pass expanded for one instance (st_pass_decl, st_passes.c):
// its names with the light index filled in.
typedef struct st_decl_pass {
    st_pass_info info; // reads and writes point into the buffers below
    int row, instance;
    char reads[256], writes[ST_NAME_MAX];
} st_decl_pass;

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
    unsigned serial;    // unique per world: identifies the instance across pass-list rebuilds
    st_decl_pass *decl; // declared passes, expanded (NULL for a plugin without a table)
    int num_decl;
    st_shader **decl_sh; // one program per table row (NULL: the row has none)
    // ABI 1.4: the declared programs (NULL until first use), each row's
    // program (-1: none) and each export's parameter (-1: a target).
    st_shader **progs;
    int *row_prog, *export_param;
} st_module_inst;

// One pass in frame order. mod == NULL is the world's regular pass.
typedef struct st_slot {
    st_module_inst *mod; // dangling between an unload and the next build_slots
    unsigned serial;     // mod's serial (0: regular), readable even then
    int pass;
    st_pass_info info;
    st_resset reads, writes; // info.reads/writes as ids
    int target;              // the world-owned target it draws into (-1: none), st_graph_target
    unsigned target_gen;     // the targets' generation `target` was resolved at
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
    st_medium_gpu medium;              // the varying density on the GPU (st_medium_gpu.c)
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
    double acc_err;                              // estimated NRMSE of the mean image
    int acc_below;                               // consecutive estimates within the tolerance
    float *acc_read;                             // read-back buffer for the convergence test
    int acc_stats;                               // stats entry "world/accumulate"
    // The adaptive mask (st_filter_mask.c): pixels that stopped accumulating.
    st_shader *acc_prefill; // writes depth 0 where frozen
    GLuint acc_mask;        // R8, 1 where frozen
    uint8_t *acc_frozen;    // the same on the CPU
    int acc_num_frozen;
    bool acc_mask_ok; // this frame's passes allow skipping frozen pixels
};

enum { RES_HDR = 0 }; // interned first by st_graph_build

static inline bool st_resset_meet(const st_resset *a, const st_resset *b) {
    for (int i = 0; i < MAX_RESOURCES / 64; i++)
        if (a->bits[i] & b->bits[i]) return true;
    return false;
}

static inline void st_resset_add(st_resset *a, const st_resset *b) {
    for (int i = 0; i < MAX_RESOURCES / 64; i++)
        a->bits[i] |= b->bits[i];
}

// st_graph.c: rebuilds the pass list (pre-passes in module order, the
// regular pass, post passes) keeping what surviving passes had pending;
// frees it; marks which passes are needed and live this frame (culling).
bool st_graph_build(st_world *w, st_err *err);
void st_graph_free(st_world *w);
void st_graph_cull(st_world *w, st_frame *f);
// The world-owned target slot s draws into (-1: none), resolved by name
// again only when the targets changed since (st_targets.gen).
int st_graph_target(st_world *w, st_slot *s);

// st_world_stats.c: the statistics entry of a pass (created on first use).
st_pass_stats *st_stats_entry(st_world *w, const char *module, const char *pass);

// st_filter.c: before a frame, restarts the sums on outside changes and sets
// the jittered matrices; false when the image has converged and nothing
// changed (no pass runs). After a frame: adds it to the sums.
bool st_filter_begin(st_world *w);
bool st_filter_accumulate(st_world *w, st_err *err);
// st_filter_mask.c
#define ST_FILTER_MASK_START 16   // frames before any pixel may stop
#define ST_FILTER_MASK_SHARE 0.25 // a pixel stops at this share of the tolerance
bool st_filter_mask_init(st_world *w, st_err *err);
void st_filter_mask_free(st_world *w);
void st_filter_mask_reset(st_world *w);
bool st_filter_masked(const st_world *w);
void st_filter_mask_update(st_world *w, const double *e2, double m, double tol);
void st_filter_mask_prefill(st_world *w);
void st_filter_mask_post(st_world *w, st_target *t, bool on);
void st_filter_mask_gate(st_world *w);

// st_passes.c: a module's passes, declared (ABI 1.3) or from its hooks.
int st_passes_count(const st_module_inst *mi);
const st_pass_info *st_passes_info(const st_module_inst *mi, int k);
// After create: expands the table, loads the programs, declares the targets.
bool st_passes_create(st_world *w, st_module_inst *mi, st_err *err);
void st_passes_destroy(st_module_inst *mi);
bool st_passes_reload(st_module_inst *mi, st_err *err);
// Declares the targets the passes write (again after a parameter change).
bool st_passes_declare_targets(st_world *w, st_module_inst *mi, st_err *err);
// The program pass k runs this frame (NULL: none): the program hook's choice,
// the row's declared program, the row's vert/frag, else the shader hook.
bool st_passes_shader(st_world *w, st_module_inst *mi, int k, const st_frame *f, st_shader **out,
                      st_err *err);
// Is `sh` one of the module's declared programs (ST_PROGRAMS)? Only those
// does the world dispatch: a compute program from the shader hook is the
// plugin's, which dispatches it itself (froxel, toth).
bool st_passes_owns(const st_module_inst *mi, const st_shader *sh);
// Program k of the module whose parameters are `params` (*out: the module).
st_shader *st_passes_program_of(st_world *w, const double *params, int k, st_module_inst **out,
                                st_err *err);
// Recompiles the programs that compile parameter k in, for its new value;
// false (nothing changed) when one does not compile.
bool st_passes_param_programs(st_world *w, st_module_inst *mi, int k, double value, st_err *err);
// Sets every module's exports (ST_EXPORTS) on `sh`.
void st_passes_apply_exports(st_world *w, st_shader *sh);
// Fills st_frame's params, shader, row and instance for pass k (mi NULL: the world's).
void st_passes_frame(const st_module_inst *mi, int k, st_frame *f);
// Sets the module's parameters as uniforms on `sh` (st_plugin.param_uniforms).
void st_passes_set_params(const st_module_inst *mi, st_shader *sh);

// st_uniforms.c: binds `sh` with every uniform the world sets on a pass's
// program (built-ins, modules' uniforms and exports, the camera's images,
// the module's param_uniforms).
void st_world_bind_pass(st_world *w, const st_module_inst *mi, st_shader *sh, const st_frame *f);
#endif
