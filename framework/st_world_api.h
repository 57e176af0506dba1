// strahl: the world as a plugin sees it (part of the plugin SDK): the scene,
// drawing it, the built-in uniforms, light defines, and the targets and
// objects the world owns or tracks for the module. Creating and running a
// world (st_world.h) is the host's business, not a plugin's.
#ifndef ST_WORLD_API_H
#define ST_WORLD_API_H
#include "st_model.h"
#include "st_module.h"

#ifdef __cplusplus
extern "C" {
#endif

const st_scene *st_world_scene(const st_world *w);
// Draws every model of the scene with `sh` (bound by the caller).
void st_world_draw(st_world *w, st_shader *sh);
// Sets every registered uniform (camera, lights, medium, modules) on `sh`,
// which must be bound. The world does this for shaders it binds itself.
void st_world_apply_uniforms(st_world *w, st_shader *sh, const st_frame *f);
// Defines for shaders that light surfaces or volumes (common/lighting.glsl,
// shadow_map/visibility.glsl): "ST_MAX_LIGHTS n" and "ST_LIGHT_TYPES m",
// m the set of the scene's light types (bit 1 << st_light_type). The code
// of absent types compiles out: llvmpipe runs both sides of a branch on a
// uniform, so a sun's cascade lookups would cost every point-lit pixel.
// Light types are fixed for a world's life (st_world_set_light moves lights
// and changes their intensity only).
const char *st_world_light_defines(const st_world *w);
// Whether a module of that name is loaded (optional providers).
bool st_world_has_module(const st_world *w, const char *module);

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

// ---- Buffers and programs owned by the world (ABI 1.4) --------------------

// Buffer `name` ("<module>.<name>"), `bytes` of dynamic storage, created on
// the first call and re-created (contents undefined) when `bytes` changes;
// data, unless NULL, is uploaded into it. Labelled, counted in
// st_world_memory and deleted when the module is switched off. 0 on failure.
GLuint st_world_buffer(st_world *w, const char *name, size_t bytes, const void *data, st_err *err);
// A buffer texture over buffer `buf` (texelFetch on a samplerBuffer), owned
// like a buffer; re-created by every call. 0 on failure.
GLuint st_world_buffer_texture(st_world *w, const char *name, GLuint buf, GLenum format,
                               st_err *err);

// The module's declared program k (st_plugin.programs), compiled on first
// use with the current parameters; `params` names the module (the array
// create received, st_frame.params). Valid until the module's next parameter
// change or shader reload. NULL (and err) when it does not compile.
st_shader *st_world_program(st_world *w, const double *params, int k, st_err *err);
// Program k bound, with every uniform the world sets on a pass's program: the
// built-ins, every module's uniforms and exports, st_hdr_in, st_gbuffer,
// st_albedo_tex and the module's param_uniforms. For a second program inside
// a pass (a draw or dispatch the plugin issues itself). When on_pass returns
// with another program bound, the world binds the pass's own program again
// (with those uniforms) before it draws or dispatches; to set uniforms or
// textures of its own on a declared pass program after using a second one,
// bind it again the same way (st_frame_use_program with its index).
st_shader *st_frame_use_program(const st_frame *f, int k, st_err *err);

#ifdef __cplusplus
}
#endif
#endif
