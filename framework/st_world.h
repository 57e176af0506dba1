// strahl: creating and running a World (the host's side: tools, tests):
// options, frames, reading the image, interactive changes, modules and
// parameters, statistics. What a plugin may call is st_world_api.h; the
// camera, models and statistics have their own headers, included here.
#ifndef ST_WORLD_H
#define ST_WORLD_H
#include "st_camera.h"
#include "st_image.h"
#include "st_stats.h"
#include "st_world_api.h"

#ifdef __cplusplus
extern "C" {
#endif

// ---- World ----------------------------------------------------------------

typedef struct st_world_opts {
    int width, height; // 0: the scene's image size
    bool timing;       // GPU timer queries per pass (for --stats)
    // The still's pixel filter. Point (0): every frame samples pixel centres.
    // Box: frames jitter the camera's sub-pixel offset (st_jitter_offset) and
    // the world accumulates their mean until it has converged (st_world_progress,
    // docs/architecture.md "Pixel filter"); any change (camera, parameters,
    // lights, size, modules) restarts it, and while a progressive module is
    // still converging each frame replaces the image instead.
    st_pixel_filter filter;
    double filter_tolerance; // box: estimated NRMSE to stop at (0: ST_FILTER_TOLERANCE; < 0: cap)
    int filter_max_frames;   // box: cap on accumulated frames (0: ST_FILTER_MAX_FRAMES)
} st_world_opts;

#define ST_FILTER_TOLERANCE 0.01
#define ST_FILTER_MIN_FRAMES 8
#define ST_FILTER_MAX_FRAMES 1024

// Sub-pixel offset of accumulated frame k of the box filter, in pixels from
// the centre, each in [-0.5, 0.5). Two interleaved sequences: even k = 2j
// takes the Halton (2, 3) point j shifted by half a pixel (toroidally), so
// k = 0 is the centre; odd k = 2j + 1 the same point under a further
// irrational shift. Each sequence's first 2^a 3^b offsets put one point in
// each cell of a 2^a x 3^b grid (shifted with them), so the even and the odd
// frames' means are two stratified estimates of the pixel whose difference
// is the convergence test's error estimate. x to the right, y down.
void st_jitter_offset(uint32_t k, float out[2]);

// Creates GL resources for the scene and loads its modules (in dependency
// order; a module whose `requires` nobody provides is an error naming both).
// The scene must outlive the world. Needs a current GL context.
st_world *st_world_create(const st_scene *scene, const st_world_opts *opts, st_err *err);
// Switches techniques in a scene before its world is created: removes the
// modules of `disable`, then adds those of `enable` and, for each, what it
// requires that no module of the scene provides (toth brings shadow_map);
// both are comma-separated names, NULL or "" for none. A module to disable
// that is not in the scene, one that another still requires, or one to
// enable that is not installed is an ST_ERR_INPUT naming it. Modules that
// are already in (enable) keep their parameters. On failure the module list
// may be partly switched (free the scene).
bool st_scene_switch_modules(st_scene *scene, const char *enable, const char *disable, st_err *err);
void st_world_destroy(st_world *w);

// Renders one frame: pre-passes, regular pass, PostProcessor chain.
bool st_world_frame(st_world *w, st_err *err);
// Reads the final image (RGB float, top row first).
bool st_world_read(st_world *w, st_image *out, st_err *err);

st_camera *st_world_camera(st_world *w);

// Interactive changes; each marks what the next frame must redo.
// Marks ST_CHANGE_* as changed for the next frame (e.g. benchmarks that
// time a technique's full cost every frame, or a scene edited in place).
void st_world_invalidate(st_world *w, unsigned changes);
void st_world_set_camera(st_world *w, const float pos[3], const float target[3], const float up[3]);
bool st_world_resize(st_world *w, int width, int height, st_err *err);
// Loads a module by name into a running world (viewer), after its
// dependencies; or unloads it. Parameters from the scene apply on load.
bool st_world_enable(st_world *w, const char *module, bool on, st_err *err);
// Sets a parameter of a loaded module (range-checked).
bool st_world_set_param(st_world *w, const char *module, const char *param, double value,
                        st_err *err);
bool st_world_get_param(const st_world *w, const char *module, const char *param, double *value);
// Convergence over every module with a progress hook: converged when all
// are, the largest frame count and error, their info lines joined. False
// when no loaded module reports progress (one frame is the final image).
bool st_world_progress(const st_world *w, st_progress *out);
// Box filter: frames in the accumulated image (0 with the point filter) and
// whether accumulation has stopped (converged or capped).
uint32_t st_world_accumulated(const st_world *w, bool *done);
// Box filter: where the still's estimated error sits, per pixel and channel:
// |A - B| / 2 for the even frames' mean A and the odd frames' B (top row
// first). At an even frame count its rms over the image's mean is the
// estimated NRMSE (st_world_progress's error); ST_ERR_INPUT with the point
// filter or before two frames are accumulated.
bool st_world_read_error(st_world *w, st_image *out, st_err *err);
// The still's pixel filter (st_world_opts.filter): box stills jitter their frames.
st_pixel_filter st_world_filter(const st_world *w);
// Moves point light i (relighting) in the world and in the scene it was
// created from; passes that depend on lights rerun.
bool st_world_set_light(st_world *w, int i, const float pos[3], const float intensity[3],
                        st_err *err);
// Recompiles every shader; on failure the old ones stay and err says why.
bool st_world_reload_shaders(st_world *w, st_err *err);

// ---- Modules and stats ---------------------------------------------------

// Module i in frame order. `params` is the instance's own array (the one its
// plugin reads): valid until that module is switched off or the world is
// destroyed; write it only through st_world_set_param.
typedef struct st_module_info {
    const st_plugin *plugin;
    double *params; // plugin->num_params values
} st_module_info;
int st_world_num_modules(const st_world *w);
st_module_info st_world_module(const st_world *w, int i);

#ifdef __cplusplus
}
#endif
#endif
