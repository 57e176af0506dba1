// strahl: GPU objects. GPUBuffer covers vertex, index, instance, uniform and
// shader-storage buffers; st_target is a framebuffer with its textures.
#ifndef ST_GPU_H
#define ST_GPU_H
#include "st_gl.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_buffer {
    GLuint id;
    GLenum target; // GL_ARRAY_BUFFER, GL_ELEMENT_ARRAY_BUFFER, GL_UNIFORM_BUFFER,
                   // GL_SHADER_STORAGE_BUFFER
    size_t size;
} st_buffer;

// Immutable storage when `dynamic` is false (static data is uploaded once).
bool st_buffer_create(st_buffer *b, GLenum target, size_t size, const void *data, bool dynamic,
                      st_err *err);
void st_buffer_destroy(st_buffer *b);

#define ST_TARGET_MAX_COLOR 4

// A framebuffer of `num_color` 2D colour textures (all of `color_format`) and
// an optional depth texture. Textures are linear-filtered, clamped.
typedef struct st_target {
    GLuint fbo;
    GLuint color[ST_TARGET_MAX_COLOR];
    GLuint depth;
    int num_color;
    int width, height;
    GLenum color_format;
} st_target;

bool st_target_create(st_target *t, int width, int height, int num_color, GLenum color_format,
                      bool with_depth, st_err *err);
void st_target_destroy(st_target *t);
// Binds for drawing and sets the viewport.
void st_target_bind(const st_target *t);

// Reads colour attachment `index` (RGBA float) into rgba (w*h*4), top row first.
bool st_target_read(const st_target *t, int index, float *rgba, st_err *err);

// The Hammersley set X_i = (i/n, radical inverse of i in base 2), i < n, as
// a 1D RG32F texture (nearest filtering); the points also go to xy (2n
// floats) unless it is NULL. Returns 0 on failure. The gathers of atlas_gi
// and ssgi sample with it.
GLuint st_hammersley_texture(int n, float *xy);

// A full-screen triangle (no vertex buffer; the vertex shader uses gl_VertexID).
void st_draw_fullscreen(void);

// Bytes of GPU memory allocated through these helpers (textures and buffers),
// for stats.
size_t st_gpu_bytes(void);
// For GL objects a module creates itself: add (or, negative, remove) bytes.
void st_gpu_track(long long delta);

#ifdef __cplusplus
}
#endif
#endif
