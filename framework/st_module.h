// strahl: the plugin ABI. A plugin is a shared object exporting one symbol,
// ST_PLUGIN_SYMBOL, a function returning a constant st_plugin descriptor.
// The loader checks abi_major (equal) and abi_minor (not newer), copies
// min(struct_size, sizeof(st_plugin)) into a zeroed descriptor so fields a
// plugin does not know about stay NULL, and names every missing required hook.
#ifndef ST_MODULE_H
#define ST_MODULE_H
#include "st_gpu.h"
#include "st_scene.h"
#include "st_shader.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ST_ABI_MAJOR 1
#define ST_ABI_MINOR 1
#define ST_PLUGIN_SYMBOL "strahl_plugin"
#define ST_MAX_PARAMS 32
#define ST_MAX_LIGHTS 8

#if defined(__GNUC__)
#define ST_EXPORT __attribute__((visibility("default")))
#else
#define ST_EXPORT
#endif

typedef struct st_world st_world;

typedef enum { ST_PARAM_FLOAT = 0, ST_PARAM_INT, ST_PARAM_BOOL, ST_PARAM_ENUM } st_param_type;

// One parameter. Values are doubles: bools 0/1, enums the index into
// `choices` ("area|thesis"). min/max bound floats and ints (inclusive).
typedef struct st_param_def {
    const char *name;
    st_param_type type;
    double def, min, max;
    const char *choices;
    const char *help;
} st_param_def;

typedef enum { ST_STAGE_PRE = 0, ST_STAGE_POST } st_stage;

enum {
    ST_PASS_SCENE = 1u << 0,       // the world draws every model with shader(pass)
    ST_PASS_FULLSCREEN = 1u << 1,  // the world draws a full-screen triangle with shader(pass)
    ST_PASS_SIDE_EFFECT = 1u << 2, // never culled (e.g. only sets uniforms or state)
};

// What a pass reads and writes, as comma-separated resource names. The
// camera's resources: "hdr" (the radiance image; post passes that write it
// draw into the next PostProcessor ping-pong target), "gbuffer" (normal.xyz,
// distance from the camera; -1 where no surface), "albedo", "depth".
// A module's own resources are named "<module>.<name>"; a provided
// capability (e.g. "shadow_map") is a resource its passes write.
typedef struct st_pass_info {
    const char *name;
    st_stage stage;
    const char *reads, *writes;
    unsigned flags;
} st_pass_info;

// What changed since a pass last ran (accumulated while it was skipped or culled).
enum {
    ST_CHANGE_FIRST = 1u << 0,    // never ran
    ST_CHANGE_GEOMETRY = 1u << 1,
    ST_CHANGE_LIGHTS = 1u << 2,
    ST_CHANGE_CAMERA = 1u << 3,
    ST_CHANGE_PARAMS = 1u << 4,   // this module's parameters
    ST_CHANGE_SIZE = 1u << 5,     // image size
    ST_CHANGE_INPUTS = 1u << 6,   // a resource this pass reads was rewritten
    ST_CHANGE_MEDIUM = 1u << 7,
    ST_CHANGE_ALL = 0xffu,
};

// Per-frame state handed to hooks. Matrices are column-major float[16].
typedef struct st_frame {
    st_world *world;
    const st_scene *scene;
    uint64_t index;   // frame counter, 0 first
    unsigned changes; // ST_CHANGE_* for this pass
    int width, height;
    const float *view, *proj, *view_proj, *inv_view_proj;
    const float *cam_pos; // float[3]
    float fov_y, near_z, far_z;
    GLuint hdr_in;                   // post passes: the current radiance image
    GLuint gbuffer, albedo, depth;   // camera targets (valid after the regular pass)
} st_frame;

// A uniform: a name and a callback that sets it on every shader that uses it
// (thesis: Uniform). `loc` is the location in `sh`.
typedef struct st_uniform {
    const char *name;
    void (*set)(void *self, st_shader *sh, GLint loc, const st_frame *f);
} st_uniform;

// A module's answer to "is your result converged, and how far off is it?"
// (the progress hook, ABI 1.1).
typedef struct st_progress {
    bool converged;  // more frames would not change the result (beyond its tolerance)
    uint32_t frames; // frames accumulated into the current result
    double error;    // estimated remaining relative error (0: exact for its model)
    char info[256];  // what the module precomputed, for --stats ("" if nothing)
} st_progress;

typedef struct st_plugin {
    uint16_t abi_major, abi_minor;
    uint32_t struct_size;
    const char *name, *description;
    const st_param_def *params;
    int num_params;
    const char *requires; // comma-separated capabilities other modules provide; "name?" is
                          // optional: no error without a provider, ordered after it with one
    const char *provides;
    // A GLSL file (relative to shaders/) included into the regular pass's
    // fragment shader; it may define ST_HAS_VISIBILITY (float
    // st_visibility(int light, vec3 p, vec3 n)), ST_HAS_INDIRECT (vec3
    // st_indirect(vec3 p, vec3 n, vec2 uv1)) or ST_HAS_COMPOSE.
    const char *regular_include;

    // Required hooks.
    void *(*create)(st_world *w, const double *params, st_err *err);
    void (*destroy)(void *self);
    int (*num_passes)(void *self);
    const st_pass_info *(*pass_info)(void *self, int pass);

    // Optional hooks (NULL = default).
    int (*uniforms)(void *self, const st_uniform **out);       // default: none
    GLuint (*rendertarget)(void *self, int pass);               // default: world's choice
    bool (*needed)(void *self, int pass, const st_frame *f);    // default: always
    bool (*on_pass)(void *self, int pass, const st_frame *f, st_err *err);
    st_shader *(*shader)(void *self, int pass);
    void (*after_pass)(void *self, int pass, const st_frame *f);
    // A parameter changed live (viewer, bench); params array already updated.
    void (*param_changed)(void *self, int index);
    // Recompile shaders from their files; keep the old ones on failure.
    bool (*reload)(void *self, st_err *err);
    void (*cleanup)(void); // once, after the last instance, before dlclose

    // ABI 1.1, optional: progressive modules report their convergence, so
    // `strahl render` can run frames until the image is converged.
    bool (*progress)(void *self, st_progress *out);
} st_plugin;

typedef const st_plugin *(*st_plugin_fn)(void);

// ---- loader -------------------------------------------------------------

typedef struct st_plugin_lib st_plugin_lib;

// Finds "<name>.so" in the module directories ($STRAHL_MODULE_PATH entries
// separated by ':', the build dir, the install dir) and checks it.
st_plugin_lib *st_plugin_open(const char *name, st_err *err);
// Opens a specific file (tests); same checks.
st_plugin_lib *st_plugin_open_file(const char *path, st_err *err);
const st_plugin *st_plugin_desc(const st_plugin_lib *lib);
void st_plugin_close(st_plugin_lib *lib); // cleanup hook, then dlclose

// Names of every loadable module in the module directories (sorted, unique).
int st_plugin_list(char names[][ST_NAME_MAX], int max);
// Module directories in search order, ':'-separated.
void st_plugin_dirs(char *out, size_t n);

// Parameter helpers: index by name (-1 if none); convert a scene value to a
// parameter value with range/type checks (messages name module.param).
int st_param_index(const st_plugin *p, const char *name);
bool st_param_from_value(const st_plugin *p, int index, const st_value *v, double *out, st_err *err);
// Formats a value for display ("0.5", "true", "area").
void st_param_format(const st_param_def *d, double v, char *out, size_t n);

#ifdef __cplusplus
}
#endif
#endif
