// strahl (internal): the world's registry of module GPU memory. Targets are
// declared by name and allocated here at the size the screen asks for;
// objects a module creates itself (buffers) are tracked by name. Both are
// labelled for debuggers and listed by st_world_memory.
#ifndef ST_TARGETS_H
#define ST_TARGETS_H
#include "st_gpu.h"
#include "st_stats.h"

#define ST_MAX_TARGETS 128
#define ST_MAX_TRACKED 128

typedef struct st_targets {
    struct {
        char name[ST_NAME_MAX];
        st_target_desc desc;
        st_target t; // t.color[0] == 0 until first use
    } t[ST_MAX_TARGETS];
    int n;
    // Bumped whenever a name, its index or a description changes, so a
    // lookup resolved by name (st_targets_written) is redone only then.
    unsigned gen;
    struct {
        char name[ST_NAME_MAX];
        GLenum identifier; // GL_BUFFER or GL_TEXTURE
        GLuint obj;
        size_t bytes;
        bool owned; // created by the registry (st_targets_buffer): deleted with its entry
    } k[ST_MAX_TRACKED];
    int nk;
} st_targets;

int st_targets_find(const st_targets *s, const char *name);
// The first target drawn into (not a 1D table) whose name is in the list
// `writes` (a pass's outputs), -1 when none.
int st_targets_written(const st_targets *s, const char *writes);
// Declares, re-describes (the texture is re-created at the next use if the
// description changed) or, with d == NULL, forgets target `name`.
bool st_targets_declare(st_targets *s, const char *name, const st_target_desc *d, st_err *err);
// Allocates target i at its size for a screen of sw x sh (no-op if it has it).
bool st_targets_ensure(st_targets *s, int i, int sw, int sh, st_err *err);
bool st_targets_track(st_targets *s, const char *name, GLenum identifier, GLuint obj, st_err *err);
void st_targets_untrack(st_targets *s, const char *name);
// A buffer the registry owns: `bytes` of dynamic storage (re-created when the
// size changes), filled from data unless NULL; 0 on failure.
GLuint st_targets_buffer(st_targets *s, const char *name, size_t bytes, const void *data,
                         st_err *err);
// A buffer texture the registry owns over buffer `buf` in `format`; 0 on failure.
// The GL name of tracked object `name` if it is of `identifier`, else 0.
GLuint st_targets_object(const st_targets *s, const char *name, GLenum identifier);
GLuint st_targets_buffer_texture(st_targets *s, const char *name, GLuint buf, GLenum format,
                                 st_err *err);
// Frees the targets and forgets the tracked objects of `module` ("<module>.*";
// NULL: all).
void st_targets_free(st_targets *s, const char *module);
// One row of the memory table for a target.
void st_targets_entry(const char *name, const st_target *t, st_mem_entry *e);
#endif
