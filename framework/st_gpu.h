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

// A framebuffer of `num_color` colour textures (all of `color_format`) and
// an optional 2D depth texture. st_target_create: 2D textures, linear-filtered,
// clamped; st_target_create_desc: any st_target_desc.
typedef struct st_target {
    GLuint fbo; // 0 for a 1D texture (a lookup table, not drawn into)
    GLuint color[ST_TARGET_MAX_COLOR];
    GLuint depth;
    int num_color;
    int width, height;
    GLenum color_format;
    // ABI 1.2
    GLenum type;  // GL_TEXTURE_2D, GL_TEXTURE_1D, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_CUBE_MAP_ARRAY
    int layers;   // array layers (a cube-map array: cubes)
    int levels;   // mip levels
    size_t bytes; // GPU memory of every texture in it
} st_target;

// What a target looks like; the world allocates one per declaration
// (st_world_declare_target). Zero fields take the default in brackets, so
// {GL_RGBA32F} is a screen-sized, linear-filtered, edge-clamped 2D texture.
typedef struct st_target_desc {
    GLenum format;    // colour format (GL_RGBA32F, GL_RGBA16F, GL_R32F, GL_R32I, ...)
    double scale;     // size as a fraction of the screen per axis [1]; at least 1 x 1
    bool depth;       // with a 2D depth texture (GL_DEPTH_COMPONENT32F) for depth tests
    bool border_zero; // taps outside the image read 0 (wrap = GL_CLAMP_TO_BORDER)
    // ABI 1.2
    GLenum type;       // GL_TEXTURE_2D [], GL_TEXTURE_1D, GL_TEXTURE_2D_ARRAY,
                       // GL_TEXTURE_CUBE_MAP_ARRAY
    int width, height; // a fixed size in texels (width > 0; 1D: width only) instead of the
                       // screen's: never resized with the window
    int divisor;       // > 1: the screen's size divided by this per axis, rounded up
                       // (instead of scale)
    int layers;        // array layers; a cube-map array's cubes (6 faces each) [1]
    int levels;        // mip levels [1]; the min filter then uses the nearest level
    GLenum filter;     // GL_LINEAR [] or GL_NEAREST, minification and magnification
    GLenum wrap;       // GL_CLAMP_TO_EDGE [], GL_CLAMP_TO_BORDER (taps outside read 0),
                       // GL_REPEAT
} st_target_desc;

bool st_target_create(st_target *t, int width, int height, int num_color, GLenum color_format,
                      bool with_depth, st_err *err);
// One colour texture (and depth) as `d` says, at width x height texels (the
// caller resolved the screen-relative size; 1D: height is ignored). Array
// targets have layer 0 attached; st_target_bind_layer picks another.
bool st_target_create_desc(st_target *t, const st_target_desc *d, int width, int height,
                           st_err *err);
void st_target_destroy(st_target *t);
// Binds for drawing and sets the viewport.
void st_target_bind(const st_target *t);
// Attaches layer `layer` of an array target's colour texture (a cube-map
// array: 6 * cube + face) and binds it for drawing.
void st_target_bind_layer(const st_target *t, int layer);
// Bytes per texel of a colour or depth format, and its short name ("RGBA32F").
size_t st_format_bytes(GLenum format);
const char *st_format_name(GLenum format);

// Reads colour attachment `index` (RGBA float) into rgba (w*h*4), top row first.
bool st_target_read(const st_target *t, int index, float *rgba, st_err *err);

// The Hammersley set X_i = (i/n, radical inverse of i in base 2), i < n:
// 2n floats into xy. The gathers of atlas_gi and ssgi sample it from a 1D
// RG32F target (st_hammersley_upload fills one).
void st_hammersley(int n, float *xy);
// Fills the first n texels of a 1D RG32F texture with the set; xy (2n
// floats) receives the points unless it is NULL. False when out of memory.
bool st_hammersley_upload(GLuint tex, int n, float *xy);

// A full-screen triangle (no vertex buffer; the vertex shader uses gl_VertexID).
void st_draw_fullscreen(void);

// Bytes of GPU memory allocated through these helpers (textures and buffers),
// in every world of the process (st_world_memory: one world's, by name).
size_t st_gpu_bytes(void);

#ifdef __cplusplus
}
#endif
#endif
