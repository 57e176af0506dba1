// strahl: the medium's varying density on the GPU (medium.density; the GLSL
// side is shaders/common/medium.glsl): the ST_DENSITY define, the height
// fog's uniforms, the grid as a 3D texture with its world-to-index map. The
// world calls these from four hooks; a homogeneous scene gets no define,
// no texture and no uniform, so its shaders and images are unchanged.
#ifndef ST_MEDIUM_GPU_H
#define ST_MEDIUM_GPU_H
#include <stddef.h>
#include "st_scene.h"
#include "st_shader.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_medium_gpu {
    st_density_kind kind; // ST_DENSITY_UNIFORM: nothing is set
    float base, falloff;  // height fog
    GLuint grid;          // R32F 3D texture, one texel per voxel (grid)
    int size[3];          // voxels per axis
    float to_local[16];   // world -> index coordinates relative to voxel 0, column major
} st_medium_gpu;

// Appends "ST_DENSITY k\n" (1 height fog, 2 grid) to the defines string of
// `cap` bytes when the scene's medium has a varying density.
void st_medium_gpu_defines(const st_scene *s, char *defines, size_t cap);
// Checks that every module of the scene models a varying density (a
// module that assumes a homogeneous medium is refused, ST_ERR_INPUT) and
// uploads the density. Needs the GL context; *m is zeroed first.
bool st_medium_gpu_create(st_medium_gpu *m, const st_scene *s, st_err *err);
void st_medium_gpu_destroy(st_medium_gpu *m);
// Sets the density uniforms and binds the grid on `sh` (in use); a no-op
// for uniforms and samplers the shader does not declare.
void st_medium_gpu_uniforms(const st_medium_gpu *m, st_shader *sh);
// Whether module `name` handles a varying density (shadow_map, which knows
// no medium, toth, froxel).
bool st_medium_gpu_module_ok(const char *name);
// False with an ST_ERR_INPUT naming the module when the scene's density
// varies and module `name` does not handle it (the world checks the scene's
// modules at creation and a module switched on later).
bool st_medium_gpu_check_module(const st_scene *s, const char *name, st_err *err);

#ifdef __cplusplus
}
#endif
#endif
