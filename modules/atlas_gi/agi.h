// atlas_gi: the plugin's state and the functions its files share (private to
// the plugin). Which file holds which concern, callers above callees (calls
// run one way, down this list):
//   atlas_gi.c      the descriptor: parameters, programs, exports; the hooks
//                   (create, passes, needed, the mode switch, param_changed,
//                   progress)
//   gbuffer.c       the G-buffer pass
//   gather.c        mode=gather: Hammersley samples, power sampling (CDF and
//                   picks), the per-frame gather, convergence
//   relight.c       mode=transfer: the transfer built from the G-buffer and
//                   its relight passes, its --stats line
//   atlas_gpu.c     the atlas on the GPU: textures and framebuffers, the
//                   G-buffer's points and model type, the regular pass'
//                   triangle table, the scene's triangles; the resolve
//   profile.c       profile=true: the relight's step times
//   atlas*.c        the CPU atlas (atlas.h); transfer*.c the transfer
#ifndef ATLAS_GI_AGI_H
#define ATLAS_GI_AGI_H
#include "atlas.h"
#include "st_bvh.h"
#include "st_world_api.h"
#include "transfer.h"
#include "transfer_gpu.h"

enum {
    P_ATLAS_SIZE,
    P_TEXELS_PER_METER,
    P_SAMPLES,
    P_ESTIMATOR,
    P_SAMPLING,
    P_VISIBILITY,
    P_BOUNCES,
    P_PROGRESSIVE,
    P_MAX_FRAMES,
    P_TOLERANCE,
    P_DISPLAY,
    P_CHART_ANGLE,
    P_MODE,
    P_TRANSFER_LEAVES,
    P_TRANSFER_EPS,
    P_PROFILE,
    P_COUNT
};

enum {
    T_POS,
    T_NORMAL,
    T_ALBEDO,
    T_L0,
    T_AREA,
    T_BOUNCE0,
    T_BOUNCE1,
    T_ACCUM,
    T_INDIRECT,
    T_COMBINED,
    T_STATS,
    T_NEAR, // 1 where a texel or one of its 8 neighbours has area (the resolve writes there)
    T_COUNT
};

// The declared programs (atlas_gi.c's table), compiled on first use.
enum {
    PR_GBUFFER,
    PR_GBUFFER_SHADOW, // with shadow_map's visibility
    PR_GBUFFER_POINTS, // one point per texel the rasterizer misses
    PR_GBUFFER_POINTS_SHADOW,
    PR_GBUFFER_L0, // the same four writing L0 alone, at the transfer's texels
    PR_GBUFFER_L0_SHADOW,
    PR_GBUFFER_L0_POINTS,
    PR_GBUFFER_L0_POINTS_SHADOW,
    PR_GATHER,
    PR_GATHER_VIS, // visibility=true: a BVH ray per sample
    PR_RESOLVE,
    PR_REDUCE, // mode=transfer: the relight's compute steps and push
    PR_LINKS,
    PR_LINKS_MEDIUM,
    PR_SUM,
    PR_PUSH,
    PR_COUNT
};

enum { AG_PROF_STEPS = 5, AG_PROF_MAX = 64 };

typedef struct agi {
    st_world *w;
    const double *p;
    atlas A;
    double extent;
    st_bvh B;
    st_bvh_gpu B_gpu;
    bool have_bvh;
    st_mesh *gmeshes; // shallow copies of A.meshes[i].mesh for the model type
    st_model_type type;
    st_model *models;
    int num_models;
    int W, H, stats_top;
    GLuint tex[T_COUNT];
    GLuint fbo_gb, fbo_l0, fbo_gather[2], fbo_resolve;
    GLuint ham_tex;
    int ham_n;
    float *ham; // the Hammersley points on the CPU (power sampling)
    // Power sampling: the per-texel probabilities and their CDFs (rows, then
    // columns within a row), built from the G-buffer's L0 and the areas.
    float *pmf;
    double *cdf_row, *cdf;
    bool have_cdf;
    GLuint pick_tex; // N picks: texel x, y, 1/(N p)
    int pick_cap;
    float *picks;
    GLuint pts_vao; // the points' vertex array (the world's buffer "atlas_gi.points")
    int num_points;
    int lookup; // 0: uv1, 1: triangle table
    // Precomputed transfer (mode=transfer), built on first use per atlas.
    transfer T;
    bool have_transfer;
    tr_gpu TG; // its GPU copy
    // profile=true: per relight step (profile.c) the last
    // AG_PROF_MAX wall and process CPU times in ms, and when the current
    // step began (CPU time: llvmpipe's work, less inflated by other
    // processes on a shared machine than the wall time).
    float prof[2][AG_PROF_STEPS][AG_PROF_MAX];
    int prof_n;
    double prof_t[2];
    double prof_gb[2][AG_PROF_STEPS]; // the G-buffer pass of this relight (step 0)
    bool shadow;                      // the G-buffer was drawn with shadow_map's visibility
    bool l0_partial; // the last G-buffer pass wrote L0 at the transfer's texels only
    bool atlas_dirty, gb_dirty, restart;
    int frames;
    bool converged;
    double rel_err;
    st_pass_info info[2];
} agi;

static inline int ip(const agi *g, int k) {
    return (int)g->p[k];
}

// gbuffer.c
bool agi_gbuffer_pass(agi *g, const st_frame *f, st_err *err);

// gather.c
bool agi_gather_pass(agi *g, const st_frame *f, st_err *err);
void agi_update_converged(agi *g);
void agi_gather_free(agi *g);

// relight.c
bool agi_transfer_pass(agi *g, const st_frame *f, st_err *err);
void agi_release_transfer(agi *g);
// The transfer's precompute and the profile's medians, for --stats.
void agi_relight_info(const agi *g, char *out, size_t size);

// atlas_gpu.c
// Builds the atlas on the CPU and everything on the GPU that depends on it
// (the transfer, which depends on it too, is the caller's to release).
bool agi_build_atlas(agi *g, st_err *err);
void agi_release_atlas_gpu(agi *g);
// Every front-side world triangle once, 9 floats each (visibility).
float *agi_scene_triangles(const agi *g, uint32_t *count, st_err *err);
// The tracked name of buffer i (--stats); 7 and 8 are the BVH's.
extern const char *const agi_buffer_names[];
// Resolve: mean (accumulated sum / frames), combined atlas, dilation, statistics.
bool agi_resolve(agi *g, st_err *err);

// profile.c
// profile=true: waits for the GPU and adds the time since the last mark to
// acc[wall, CPU][step] (NULL: only starts the clock). Without profile:
// nothing, no wait.
void agi_prof_mark(agi *g, double (*acc)[AG_PROF_STEPS], int step);
// Keeps a relight's step times (ms[wall, CPU][step]) among the last AG_PROF_MAX.
void agi_prof_keep(agi *g, double (*ms)[AG_PROF_STEPS]);
// Appends the steps' medians to out (length n of size), if any were kept.
void agi_prof_info(const agi *g, char *out, int n, size_t size);
#endif
