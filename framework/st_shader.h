// strahl: GLSL programs from files under shaders/, with `#include "dir/file"`
// resolved against the shader root and compile/link errors reported with the
// original file and line.
#ifndef ST_SHADER_H
#define ST_SHADER_H
#include "st_gl.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ST_SHADER_CACHE 64

typedef struct st_shader {
    GLuint program;
    char vs[128], fs[128], cs[128]; // paths relative to the shader root
    char defines[2048];             // "NAME VALUE" lines after #version; `#include "f"` lines
                                    // are expanded there in fragment/compute stages
    int next_unit;                  // next free texture unit while in use
    int num_cached;
    struct {
        char name[64];
        GLint loc;
    } cache[ST_SHADER_CACHE];
    char gs[128]; // geometry stage, "" without one
} st_shader;

// The shader root: $STRAHL_SHADER_PATH, else the installed tree this
// libstrahl belongs to, else the source tree, else the configured install dir
// (the first that has common/).
const char *st_shader_root(void);
// Files below `prefix`/ ("height_fog/fog.frag" for prefix "height_fog") are
// read from `dir` instead of the root: how a plugin outside the tree ships
// its own GLSL (the loader registers <module dir>/shaders/<name>/ when it
// exists).
// Returns false if the table is full or the arguments are too long.
bool st_shader_add_dir(const char *prefix, const char *dir);

// Vertex + fragment program. `defines` may be NULL.
st_shader *st_shader_load(const char *vs, const char *fs, const char *defines, st_err *err);
// Vertex + geometry + fragment program (`gs` gets no module includes, as the
// vertex stage).
st_shader *st_shader_load_gs(const char *vs, const char *gs, const char *fs, const char *defines,
                             st_err *err);
st_shader *st_shader_load_compute(const char *cs, const char *defines, st_err *err);
// A plain program from in-memory sources (no includes), for tools whose own
// shaders must not depend on the shader folder (the viewer's display).
GLuint st_program_from_source(const char *vs, const char *fs, const char *what, st_err *err);
// Recompiles from the files; on failure the old program stays and err says why.
bool st_shader_reload(st_shader *sh, st_err *err);
void st_shader_destroy(st_shader *sh);

// Binds the program and resets texture units.
void st_shader_use(st_shader *sh);
GLint st_shader_loc(st_shader *sh, const char *name); // cached; -1 if unused
// Binds `tex` to the next free unit and sets sampler `name`; no-op if unused.
void st_shader_texture(st_shader *sh, const char *name, GLenum target, GLuint tex);
void st_shader_set_int(st_shader *sh, const char *name, int v);
void st_shader_set_float(st_shader *sh, const char *name, float v);
void st_shader_set_vec2(st_shader *sh, const char *name, float x, float y);
void st_shader_set_vec3(st_shader *sh, const char *name, const float *v);
void st_shader_set_mat4(st_shader *sh, const char *name, const float *m);

// Preprocesses one file (exposed for tests): resolves includes, inserts
// #line directives; file ids index `names` (at most 32).
char *st_shader_preprocess(const char *path, const char *defines, char names[][128], int *num_names,
                           st_err *err);
// Same for one stage: defines ST_VERTEX/ST_FRAGMENT/ST_COMPUTE, and expands
// `#include "file"` lines of `defines` (module includes) in the fragment and
// compute stages only.
char *st_shader_preprocess_stage(const char *path, const char *defines, GLenum stage,
                                 char names[][128], int *num_names, st_err *err);

#ifdef __cplusplus
}
#endif
#endif
