// strahl: the plugin ABI. A plugin is a shared object exporting one symbol,
// ST_PLUGIN_SYMBOL, a function returning a constant st_plugin descriptor.
// The loader checks abi_major (equal) and abi_minor (not newer), copies
// min(struct_size, sizeof(st_plugin)) into a zeroed descriptor so fields a
// plugin does not know about stay NULL, and names every missing required hook.
// docs/architecture.md explains the frame graph around it.
//
// A minimal plugin (one post pass that scales the image; its shader
// "dim/dim.frag" lives in shaders/dim/ in the tree, or in
// <module dir>/shaders/dim/ beside dim.so out of it; examples/plugin builds
// one against an installed strahl with find_package(strahl)):
//
//   #include <st_world_api.h>
//   #include <stdlib.h>
//   static const st_param_def params[] = {{"gain", ST_PARAM_FLOAT, 0.5, 0, 1, NULL, "scale"}};
//   // The world loads, reloads and deletes the program, binds it with every
//   // uniform, sets the parameter as the uniform u_gain and draws a triangle.
//   static const st_pass_decl passes[] = {
//       {{"dim", ST_STAGE_POST, "hdr", "hdr", ST_PASS_FULLSCREEN}, .frag = "dim/dim.frag"}};
//   ST_PLUGIN(.name = "dim", .description = "scales the image", ST_PARAMS(params),
//             ST_PASSES(passes), .param_uniforms = "u_")
//
// with dim.frag reading `uniform sampler2D st_hdr_in;` (bound by the world).
// on_pass(k, f) sets what the parameters do not say, on f->shader.
//
// ABI 1.4 lets the tables say what real techniques need (docs/plugin-guide.md
// walks through one): several programs (ST_PROGRAMS; compute ones too, with
// parameters compiled in as defines), a compute pass the world dispatches
// over the target it writes, a program hook choosing a pass's program per
// frame, uniforms exported to every program (ST_EXPORTS) and buffers the
// world owns. A plugin whose pass list itself changes with its parameters
// may still answer num_passes and pass_info, as before ABI 1.3.
//
// Order of the hooks:
//   load:     parameters = defaults, then the scene's values
//   create(w, params), then uniforms() once              (in dependency order)
//   declared passes: the table expanded, the rows' programs loaded, targets
//     declared (other declared programs compile on first use)
//   num_passes(), pass_info(k) for every k               (again after every switch
//                                                         and every parameter change;
//                                                         not with declared passes)
//   per frame, per pass in frame order: needed(k, f)     (all passes first)
//   per live, needed pass: the world binds rendertarget(k) (or the next post
//     target for a post pass writing "hdr", or else the world-owned target
//     the pass writes, allocated at its size); shader(k) is bound with every
//     uniform set (program(k, f) picks a declared one); on_pass(k, f); the world
//     draws (ST_PASS_SCENE: every model, ST_PASS_FULLSCREEN: one triangle) or,
//     for a declared compute program, dispatches; after_pass(k, f)
//   st_world_set_param: the programs that compile the parameter in are rebuilt
//     (a value that does not compile is refused), the value lands in params[],
//     then param_changed(i), then the declared targets are declared again
//   st_world_reload_shaders: the declared programs, then reload()
//   destroy(self); after the last instance of the .so: cleanup(), dlclose
#ifndef ST_MODULE_H
#define ST_MODULE_H
#include "st_gpu.h"
#include "st_scene.h"
#include "st_shader.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ST_ABI_MAJOR 1
#define ST_ABI_MINOR 4
#define ST_PLUGIN_SYMBOL "strahl_plugin"
#define ST_MAX_PARAMS 32
#define ST_MAX_LIGHTS 8
#define ST_MAX_PROGRAMS 32 // declared programs per plugin
// A capability token in st_plugin.provides: the technique computes the
// medium's in-scattered light and adds it to the image (toth, froxel). Two of
// them in one world would add it twice, so a world refuses a second one
// unless the scene opts in with "inscatter_overlay": true.
#define ST_CAP_INSCATTER "inscatter"

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
    // ABI 1.4: a pass whose declared program (ST_PROGRAMS) is a compute program
    // is dispatched over the first target it writes (bound as image unit 0;
    // a compute program from the shader hook the plugin dispatches itself),
    // one invocation per texel and layer; with ST_PASS_PLANE per texel only
    // (the program loops over the layers itself).
    ST_PASS_PLANE = 1u << 3,
    // The pass reads the camera's images ("hdr", "gbuffer", "albedo",
    // "depth") only at the pixel it writes. A box still that runs to
    // convergence stops accumulating pixels whose error is far below its
    // tolerance and, while every pass of a frame that reads those images is
    // pixel-local, the regular pass and the full-screen post passes onto
    // "hdr" skip them (their fragments there fail a depth test). Without it
    // the frame shades every pixel: a pass that gathers from neighbouring
    // pixels would read skipped ones. Older hosts ignore it.
    ST_PASS_PIXEL_LOCAL = 1u << 4,
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

// st_target_desc (what a target looks like): st_gpu.h.

// A declared pass (ABI 1.3): what st_pass_info says, plus the program the
// world loads, hot-reloads and destroys for it, and the target it writes,
// which the world declares, allocates, resizes and frees. A plugin lists
// them in a static table (ST_PASSES) instead of num_passes/pass_info code.
// With count ST_PER_LIGHT the row is one pass per light of the scene, and
// "%d" in its name lists (reads, writes) is the light's index. Rows expand in
// table order: pass k of row r is hook index (passes of earlier rows) + k;
// st_frame's row and instance say which.
#define ST_PER_LIGHT (-1)
typedef struct st_pass_decl {
    st_pass_info info;
    const char *vert, *frag; // program files; vert NULL: "common/fullscreen.vert"; frag NULL:
                             // no program (the plugin draws with its own, or the shader hook)
    const char *defines;     // compile defines ("NAME VALUE" lines), NULL for none
    int count;               // 0 or 1: one pass; ST_PER_LIGHT: one per light
    st_target_desc target;   // format != 0: the target `writes` names (one "<module>.<x>")
    const char *scale_param; // a FLOAT parameter whose value is target.scale (re-declared when
                             // it changes); NULL: target.scale as given
    // ABI 1.4: the pass's program, by name, from st_plugin.programs (instead of
    // vert/frag); the program hook may pick another one per frame.
    const char *program;
} st_pass_decl;

// A program the world compiles on first use, hot-reloads and deletes for the
// module (ABI 1.4). Graphics: vert (NULL: "common/fullscreen.vert") and frag;
// compute: comp. Parameters named in param_defines are compiled in as
// "<MODULE>_<PARAM> <value>" (upper case; ints, bools and enum indices as
// integers, floats as %.9g) and the program is recompiled when one of them
// changes (the change is refused, the value kept, if it does not compile).
enum {
    ST_PROGRAM_LIGHTS = 1u << 0, // prepend st_world_light_defines (light types, medium density)
};
typedef struct st_program_decl {
    const char *name;          // what passes and messages call it
    const char *vert, *frag;   // a graphics program
    const char *comp;          // or a compute program
    const char *defines;       // fixed defines ("NAME VALUE" lines), NULL for none
    const char *param_defines; // comma-separated parameter names
    unsigned flags;            // ST_PROGRAM_*
} st_program_decl;

// A uniform a module exports to every program the world binds, its own and
// other modules' (ABI 1.4): a parameter's value (set as the uniform's GLSL
// type: float, int or bool) or one of the module's targets (bound as a texture
// of the target's type; allocated on first use) or, where no target has that
// name, its buffer texture of that name (st_world_buffer_texture; bound as a
// GL_TEXTURE_BUFFER, 0 while there is none). Exactly one of param and
// target is set. Values the table cannot say stay st_uniform callbacks.
typedef struct st_export_decl {
    const char *uniform;
    const char *param;
    const char *target;
} st_export_decl;

// What changed since a pass last ran (accumulated while it was skipped or culled).
enum {
    ST_CHANGE_FIRST = 1u << 0, // never ran
    ST_CHANGE_GEOMETRY = 1u << 1,
    ST_CHANGE_LIGHTS = 1u << 2,
    ST_CHANGE_CAMERA = 1u << 3,
    ST_CHANGE_PARAMS = 1u << 4, // this module's parameters
    ST_CHANGE_SIZE = 1u << 5,   // image size
    ST_CHANGE_INPUTS = 1u << 6, // a resource this pass reads was rewritten
    ST_CHANGE_MEDIUM = 1u << 7,
    ST_CHANGE_ALL = 0xffu,
    // With ST_CHANGE_CAMERA: every camera change since the pass last ran was
    // the box filter's sub-pixel jitter within one accumulation (the view and
    // the scene are those of the accumulation's first frame). Not in
    // ST_CHANGE_ALL: it qualifies a change, it is none itself.
    ST_CHANGE_JITTER = 1u << 8,
    // ABI 1.4: the world's shaders were reloaded from their files
    // (st_world_reload_shaders): a pass whose result stays until its inputs
    // change runs again to show the edited program. Not in ST_CHANGE_ALL.
    ST_CHANGE_PROGRAMS = 1u << 9,
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
    GLuint hdr_in;                 // post passes: the current radiance image
    GLuint gbuffer, albedo, depth; // camera targets (valid after the regular pass)
    // ABI 1.3: the module's parameters (the array create received); for a
    // declared pass (needed, on_pass, after_pass) the program the world
    // loaded and bound for it (NULL without one), its table row and its
    // instance (the light of an ST_PER_LIGHT row, else 0).
    const double *params;
    st_shader *shader;
    int row, instance;
    // ABI 1.4: the still's pixel filter (box stills accumulate jittered frames)
    // and this frame's sub-pixel offset in pixels (0, 0 with the point filter).
    st_pixel_filter filter;
    float jitter[2];
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
    char info[512];  // what the module precomputed, for --stats ("" if nothing)
} st_progress;

typedef struct st_plugin {
    uint16_t abi_major, abi_minor;
    uint32_t struct_size;
    const char *name, *description;
    const st_param_def *params;
    int num_params;
    const char *requires; // comma-separated capabilities other modules provide; "name?" is
                          // optional: no error without a provider, ordered after it with one
    const char *provides; // capabilities: ones others require, and ST_CAP_INSCATTER
    // A GLSL file (relative to shaders/) included into the regular pass's
    // fragment shader; it may define ST_HAS_VISIBILITY (float
    // st_visibility(int light, vec3 p, vec3 n)), ST_HAS_INDIRECT (vec3
    // st_indirect(vec3 p, vec3 n, vec2 uv1)) or ST_HAS_COMPOSE.
    const char *regular_include;

    // Required hooks (create and destroy optional with declared passes).
    void *(*create)(st_world *w, const double *params, st_err *err);
    void (*destroy)(void *self);
    int (*num_passes)(void *self);
    const st_pass_info *(*pass_info)(void *self, int pass);

    // Optional hooks (NULL = default).
    int (*uniforms)(void *self, const st_uniform **out);     // default: none
    GLuint (*rendertarget)(void *self, int pass);            // default: world's choice
    bool (*needed)(void *self, int pass, const st_frame *f); // default: always
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

    // ABI 1.1: the light types the technique handles (ST_LIGHT_BIT mask);
    // 0 = point lights only. The world refuses a scene with any other type.
    unsigned light_types;

    // ABI 1.3: declared passes (ST_PASSES(table)); with them num_passes and
    // pass_info are not needed (and not called), and neither are create and
    // destroy for a plugin without state of its own (st_frame has the world
    // and the parameters). A plugin built against an older minor version has
    // none and keeps the hooks.
    const st_pass_decl *passes;
    int num_pass_decls;
    // ABI 1.3: a prefix ("u_"): before on_pass the world sets each parameter
    // on a declared pass's program as the uniform prefix + name, if the
    // program has it (float uniforms as float, int and bool as int).
    const char *param_uniforms;

    // ABI 1.4: programs the world compiles and owns (ST_PROGRAMS(table));
    // st_pass_decl.program names one, st_world_program / st_frame_use_program
    // hand out any by its index.
    const st_program_decl *programs;
    int num_programs;
    // ABI 1.4: uniforms set from the module's parameters and targets on every
    // program the world binds (ST_EXPORTS(table)).
    const st_export_decl *exports;
    int num_exports;
    // ABI 1.4, optional: the program (index into programs) declared pass k
    // runs this frame, where it depends on the frame or the parameters; -1:
    // none (the plugin draws with its own calls). Default: the row's program.
    int (*program)(void *self, int pass, const st_frame *f);
} st_plugin;

typedef const st_plugin *(*st_plugin_fn)(void);

// Pointer lifetimes (what a plugin may keep, and for how long):
// - `params` given to create: this instance's own array of num_params values,
//   at one address from create until destroy returns, whatever modules are
//   loaded, unloaded or re-ordered meanwhile. The world writes it (scene
//   values before create, st_world_set_param later, then param_changed); the
//   plugin only reads it. Keep the pointer, do not copy the values.
// - `w` given to create: valid until destroy returns.
// - st_frame and everything it points to (matrices, cam_pos, scene): valid
//   during the hook call only; textures in it may be re-created on resize.
// - What the plugin returns (st_pass_info and its strings, st_uniform tables,
//   st_shader*) must stay valid until the next call of the same hook or until
//   destroy; the world copies st_pass_info when it rebuilds the pass list
//   (after create, after a switch, after every set_param) and keeps the
//   strings it points to until the next rebuild.
// - Targets (st_world_declare_target, st_world_api.h): a plugin creates no
//   textures; it declares each by name (format, size or screen scale or
//   divisor, type and layers, mip levels, filter, wrap, depth: st_target_desc
//   in st_gpu.h) from create, param_changed or needed (needed runs before
//   the world binds targets: toth re-declares there when a new image height
//   moves its divisor), and the world allocates,
//   resizes, binds, accounts and frees it. The st_target* that
//   st_world_target returns and its GL names are valid until the next frame,
//   resize or re-declaration of that name; fixed-size targets keep their GL
//   names until re-declared with another description. Buffers the plugin
//   creates itself are its own, tracked by name (st_world_track) from
//   creation until st_world_untrack or until the module is switched off.
// - The st_plugin descriptor and the parameter table: static in the plugin;
//   the loader copies the descriptor, not the tables, so they live as long as
//   the .so (until after cleanup).

// ---- struct sizes ---------------------------------------------------------
// Besides st_plugin (abi_major/minor, struct_size), these structs cross the
// plugin boundary. ST_PLUGIN exports the sizes the plugin was compiled with
// as a second symbol; the loader refuses a plugin whose st_param_def,
// st_pass_info, st_uniform, st_light_desc, st_mesh, st_target, st_buffer or
// st_err (embedded, filled or indexed as arrays) differ from its own, or
// whose st_frame, st_scene or st_shader (allocated by strahl, read through a
// pointer) are larger than its own, naming the struct. A plugin without the
// symbol is checked by abi_major/abi_minor alone. Fields are only appended.
#define ST_PLUGIN_SIZES_SYMBOL "strahl_plugin_sizes"

typedef struct st_abi_sizes {
    uint32_t struct_size; // sizeof(st_abi_sizes): fields past it are unknown to the plugin
    uint32_t plugin, param_def, pass_info, uniform, frame, scene, light_desc, mesh, shader, target,
        buffer, err, target_desc;
    uint32_t pass_decl;                 // ABI 1.3
    uint32_t program_decl, export_decl; // ABI 1.4
} st_abi_sizes;

#define ST_ABI_SIZES                                                                               \
    {                                                                                              \
        sizeof(st_abi_sizes), sizeof(st_plugin), sizeof(st_param_def), sizeof(st_pass_info),       \
            sizeof(st_uniform), sizeof(st_frame), sizeof(st_scene), sizeof(st_light_desc),         \
            sizeof(st_mesh), sizeof(st_shader), sizeof(st_target), sizeof(st_buffer),              \
            sizeof(st_err), sizeof(st_target_desc), sizeof(st_pass_decl), sizeof(st_program_decl), \
            sizeof(st_export_decl)                                                                 \
    }
typedef const st_abi_sizes *(*st_abi_sizes_fn)(void);

// ---- declaring a plugin -----------------------------------------------------
// ST_PLUGIN(designated initializers of st_plugin) defines the descriptor with
// the ABI version and size filled in, and exports both symbols the loader
// looks for. ST_PARAMS(table) sets .params and .num_params from a static array.
#define ST_PARAMS(table) .params = (table), .num_params = (int)(sizeof(table) / sizeof((table)[0]))
// ST_PASSES(table) sets .passes and .num_pass_decls from a static array of st_pass_decl.
#define ST_PASSES(table)                                                                           \
    .passes = (table), .num_pass_decls = (int)(sizeof(table) / sizeof((table)[0]))
// ST_PROGRAMS(table), ST_EXPORTS(table): the same for st_program_decl and st_export_decl.
#define ST_PROGRAMS(table)                                                                         \
    .programs = (table), .num_programs = (int)(sizeof(table) / sizeof((table)[0]))
#define ST_EXPORTS(table)                                                                          \
    .exports = (table), .num_exports = (int)(sizeof(table) / sizeof((table)[0]))
#define ST_PLUGIN(...)                                                                             \
    static const st_plugin st_plugin_descriptor_ = {.abi_major = ST_ABI_MAJOR,                     \
                                                    .abi_minor = ST_ABI_MINOR,                     \
                                                    .struct_size = sizeof(st_plugin),              \
                                                    __VA_ARGS__};                                  \
    ST_EXPORT const st_plugin *strahl_plugin(void) {                                               \
        return &st_plugin_descriptor_;                                                             \
    }                                                                                              \
    ST_EXPORT const st_abi_sizes *strahl_plugin_sizes(void) {                                      \
        static const st_abi_sizes sizes = ST_ABI_SIZES;                                            \
        return &sizes;                                                                             \
    }

// ---- loader -------------------------------------------------------------

typedef struct st_plugin_lib st_plugin_lib;

// Finds "<name>.so" in the module directories ($STRAHL_MODULE_PATH entries
// separated by ':', then the build dir for a strahl run from its build tree,
// the install dir for an installed one) and checks it.
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
bool st_param_from_value(const st_plugin *p, int index, const st_value *v, double *out,
                         st_err *err);
// Formats a value for display ("0.5", "true", "area").
void st_param_format(const st_param_def *d, double v, char *out, size_t n);
// An enum's choices ("area|thesis"): how many, and the k-th name (false and
// "" past the end).
int st_param_num_choices(const st_param_def *d);
bool st_param_choice(const st_param_def *d, int k, char *out, size_t n);

#ifdef __cplusplus
}
#endif
#endif
