// strahl: the World (models, modules, uniforms, frame), ModelType/Model,
// Camera with its PostProcessor, Light. Mirrors the thesis' framework roles.
#ifndef ST_WORLD_H
#define ST_WORLD_H
#include "st_image.h"
#include "st_module.h"

#ifdef __cplusplus
extern "C" {
#endif

// ---- ModelType / Model ----------------------------------------------------

// Where one attribute lives in an interleaved vertex (thesis: VertexAttribute).
typedef struct st_vertex_attr {
    const char *name; // shader variable, e.g. "st_position"
    GLuint location;
    int components; // floats
    size_t offset;  // bytes into the vertex
} st_vertex_attr;

// Per-instance attribute (thesis: InstanceAttribute), divisor 1.
typedef struct st_instance_attr {
    const char *name;
    GLuint location;
    int components;
    size_t offset;
} st_instance_attr;

#define ST_MAX_ATTRS 8

// Models of one type share one vertex buffer and one index buffer.
typedef struct st_model_type {
    char name[ST_NAME_MAX];
    st_vertex_attr attrs[ST_MAX_ATTRS];
    int num_attrs;
    size_t stride;
    st_instance_attr inst_attrs[ST_MAX_ATTRS];
    int num_inst_attrs;
    size_t inst_stride;
    GLenum primitive;
    st_buffer vbo, ibo, instances;
    GLuint vao;
} st_model_type;

typedef struct st_model {
    st_model_type *type;
    const st_mesh *mesh; // the scene mesh it came from
    int32_t base_vertex;
    uint32_t first_index, index_count;
    float model[16], normal_matrix[9];
    float albedo[3], emission[3];
    bool double_sided;
} st_model;

// The standard layout: st_position (0, vec3), st_normal (1, vec3), st_uv1 (2, vec2).
enum { ST_ATTR_POSITION = 0, ST_ATTR_NORMAL = 1, ST_ATTR_UV1 = 2 };

// Builds one model type with the standard layout from meshes; `uv1` may
// override each mesh's lightmap UVs (2 floats per vertex, concatenated in mesh
// order) for modules that generate their own atlas. models[i] gets mesh i.
bool st_model_type_build(st_model_type *t, const char *name, const st_mesh *meshes, int n,
                         const float *uv1, st_model *models, st_err *err);
void st_model_type_destroy(st_model_type *t);
// Draws models with `sh` bound, setting st_model, st_normal_matrix, st_albedo,
// st_emission, st_double_sided per model.
void st_model_type_draw(const st_model_type *t, const st_model *models, int n, st_shader *sh);

// ---- Camera / PostProcessor ---------------------------------------------

typedef struct st_camera {
    float position[3], target[3], up[3];
    float fov_y, near_z, far_z;
    int width, height;
    float view[16], proj[16], view_proj[16], inv_view_proj[16];
    // The regular pass draws into `scene` (0 radiance, 1 gbuffer, 2 albedo,
    // depth); the PostProcessor ping-pongs between post[0] and post[1].
    st_target scene, post[2];
    int post_out;   // index of the post target the next pass writes
    GLuint current; // texture holding the latest image (with a box filter: the accumulated mean)
    // Box filter only: running sums (colour 0: RGB, A = sum of luminance^2)
    // and the mean image (colour 1), ping-ponged frame to frame.
    st_target accum[2];
} st_camera;

void st_camera_update(st_camera *c); // recompute matrices from pose and size

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
    double filter_tolerance; // box: relative standard error to stop at (0: ST_FILTER_TOLERANCE)
    int filter_max_frames;   // box: cap on accumulated frames (0: ST_FILTER_MAX_FRAMES)
} st_world_opts;

#define ST_FILTER_TOLERANCE 0.005
#define ST_FILTER_MAX_FRAMES 64

// Sub-pixel offset of accumulated frame k of the box filter, in pixels from
// the centre, each in [-0.5, 0.5): the Halton (2, 3) point k shifted by half a
// pixel (toroidally), so k = 0 is the centre and the first 2^a 3^b offsets
// put one point in each cell of a 2^a x 3^b grid (shifted with them). x to
// the right, y down the image.
void st_jitter_offset(uint32_t k, float out[2]);

// Creates GL resources for the scene and loads its modules (in dependency
// order; a module whose `requires` nobody provides is an error naming both).
// The scene must outlive the world. Needs a current GL context.
st_world *st_world_create(const st_scene *scene, const st_world_opts *opts, st_err *err);
void st_world_destroy(st_world *w);

// Renders one frame: pre-passes, regular pass, PostProcessor chain.
bool st_world_frame(st_world *w, st_err *err);
// Reads the final image (RGB float, top row first).
bool st_world_read(st_world *w, st_image *out, st_err *err);

// Draws every model of the scene with `sh` (bound by the caller).
void st_world_draw(st_world *w, st_shader *sh);
// Sets every registered uniform (camera, lights, medium, modules) on `sh`,
// which must be bound. The world does this for shaders it binds itself.
void st_world_apply_uniforms(st_world *w, st_shader *sh, const st_frame *f);
const st_scene *st_world_scene(const st_world *w);
st_camera *st_world_camera(st_world *w);
// Defines for shaders that light surfaces or volumes (common/lighting.glsl,
// shadow_map/visibility.glsl): "ST_MAX_LIGHTS n" and "ST_LIGHT_TYPES m",
// m the set of the scene's light types (bit 1 << st_light_type). The code
// of absent types compiles out: llvmpipe runs both sides of a branch on a
// uniform, so a sun's cascade lookups would cost every point-lit pixel.
// Light types are fixed for a world's life (st_world_set_light moves lights
// and changes their intensity only).
const char *st_world_light_defines(const st_world *w);

// Interactive changes; each marks what the next frame must redo.
// Marks ST_CHANGE_* as changed for the next frame (e.g. benchmarks that
// time a technique's full cost every frame, or a scene edited in place).
void st_world_invalidate(st_world *w, unsigned changes);
void st_world_set_camera(st_world *w, const float pos[3], const float target[3], const float up[3]);
bool st_world_resize(st_world *w, int width, int height, st_err *err);
// Loads a module by name into a running world (viewer), after its
// dependencies; or unloads it. Parameters from the scene apply on load.
bool st_world_enable(st_world *w, const char *module, bool on, st_err *err);
bool st_world_has_module(const st_world *w, const char *module);
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
// Moves point light i (relighting) in the world and in the scene it was
// created from; passes that depend on lights rerun.
bool st_world_set_light(st_world *w, int i, const float pos[3], const float intensity[3],
                        st_err *err);
// Recompiles every shader; on failure the old ones stay and err says why.
bool st_world_reload_shaders(st_world *w, st_err *err);

// ---- Targets owned by the world ------------------------------------------

// Every texture a pass draws into or a module samples is declared by name
// (st_target_desc, st_gpu.h: format, screen scale or divisor or a fixed size,
// type and layers, mip levels, filter, wrap, depth). The world allocates it
// at first use, re-creates it when the description or (for screen-relative
// sizes) the screen size changes, labels it with its name for debuggers,
// counts it in st_world_memory, binds it for a pass whose `writes` names it
// (unless the module has a rendertarget hook) and frees it when the module is
// switched off. Modules do not create or patch textures themselves.
//
// Declares (or re-describes) target `name`, which must be "<module>.<name>"
// like the pass resources; d == NULL forgets it (frees the texture). Call from
// create and again when a parameter changes the description.
bool st_world_declare_target(st_world *w, const char *name, const st_target_desc *d, st_err *err);
// The target, allocated at the current size; NULL if undeclared or the
// allocation failed (st_world_get_target says why). The pointer and its GL
// names are valid until the next frame, resize, or declare of this name;
// fixed-size targets keep their GL names until re-declared differently.
const st_target *st_world_target(st_world *w, const char *name);
const st_target *st_world_get_target(st_world *w, const char *name, st_err *err);
// Declares and returns the target allocated, in one call: for fixed-size
// textures a module fills itself (atlases, lookup tables).
const st_target *st_world_alloc_target(st_world *w, const char *name, const st_target_desc *d,
                                       st_err *err);

// GL objects a module creates itself (identifier GL_BUFFER, or GL_TEXTURE
// for a buffer texture, which holds no memory of its own; other textures
// are declared as targets) are tracked by name ("<module>.<name>"): labelled
// for debuggers and counted in st_world_memory (the world reads their size
// from GL). Track after creating the object, untrack before deleting it;
// switching the module off forgets its entries.
bool st_world_track(st_world *w, const char *name, GLenum identifier, GLuint obj, st_err *err);
void st_world_untrack(st_world *w, const char *name);

// One row of the GPU memory table: a target, a tracked object, a camera
// target or the scene's geometry.
typedef struct st_mem_entry {
    char name[ST_NAME_MAX];
    char owner[ST_NAME_MAX]; // the module; "camera", "world" for the world's own
    char format[32];         // "RGBA32F", "3xRGBA32F+D32F" (colour textures, depth); "-"
    const char *kind;        // "2D", "1D", "2D array", "cube array", "buffer", "buffer texture"
    int width, height, layers, levels; // 0 for buffers
    size_t bytes;                      // 0 for a target not allocated yet
} st_mem_entry;
// The world's GPU memory, every row: fills at most max of them (out may be
// NULL) and returns how many there are. Rows of one owner are adjacent.
int st_world_memory(st_world *w, st_mem_entry *out, int max);
// Their sum.
size_t st_world_memory_bytes(st_world *w);

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

#define ST_STATS_MAX_SAMPLES 4096

typedef struct st_pass_stats {
    char module[ST_NAME_MAX], pass[ST_NAME_MAX];
    uint32_t runs, skipped, culled;
    bool ran_last_frame, culled_last_frame;
    int num_samples;
    float gpu_ms[ST_STATS_MAX_SAMPLES], cpu_ms[ST_STATS_MAX_SAMPLES];
} st_pass_stats;

int st_world_num_pass_stats(const st_world *w);
const st_pass_stats *st_world_pass_stats(const st_world *w, int i);
void st_world_reset_stats(st_world *w);
// Drops timing samples (after warm-up) but keeps run/skip/cull counts.
void st_world_reset_samples(st_world *w);
double st_median_f(const float *v, int n);
double st_median_d(const double *v, int n);

#ifdef __cplusplus
}
#endif
#endif
