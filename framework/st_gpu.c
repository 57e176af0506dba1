#include "st_gpu.h"
#include <stdlib.h>
#include <string.h>

static size_t g_bytes;
static GLuint g_empty_vao;

size_t st_gpu_bytes(void) {
    return g_bytes;
}

size_t st_format_bytes(GLenum f) {
    switch (f) {
    case GL_RGBA32F:
    case GL_RGBA32I:
        return 16;
    case GL_RGBA16F:
    case GL_RG32F:
    case GL_RG32I:
        return 8;
    case GL_R32F:
    case GL_R32I:
    case GL_RG16F:
    case GL_RGBA8:
    case GL_DEPTH_COMPONENT32F:
        return 4;
    case GL_R16F:
        return 2;
    case GL_R8:
        return 1;
    default:
        return 16;
    }
}

const char *st_format_name(GLenum f) {
    switch (f) {
    case GL_RGBA32F:
        return "RGBA32F";
    case GL_RGBA32I:
        return "RGBA32I";
    case GL_RGBA16F:
        return "RGBA16F";
    case GL_RG32F:
        return "RG32F";
    case GL_RG32I:
        return "RG32I";
    case GL_R32F:
        return "R32F";
    case GL_R32I:
        return "R32I";
    case GL_RG16F:
        return "RG16F";
    case GL_RGBA8:
        return "RGBA8";
    case GL_DEPTH_COMPONENT32F:
        return "D32F";
    case GL_R16F:
        return "R16F";
    case GL_R8:
        return "R8";
    default:
        return "?";
    }
}

bool st_buffer_create(st_buffer *b, GLenum target, size_t size, const void *data, bool dynamic,
                      st_err *err) {
    memset(b, 0, sizeof *b);
    glCreateBuffers(1, &b->id);
    // An empty buffer still gets 16 bytes of storage, but nothing to copy.
    glNamedBufferStorage(b->id, (GLsizeiptr)(size ? size : 16), size ? data : NULL,
                         dynamic ? GL_DYNAMIC_STORAGE_BIT : 0);
    b->target = target;
    b->size = size;
    g_bytes += size;
    return st_gl_check("buffer storage", err);
}

void st_buffer_destroy(st_buffer *b) {
    if (!b->id) return;
    glDeleteBuffers(1, &b->id);
    g_bytes -= b->size;
    memset(b, 0, sizeof *b);
}

bool st_target_create(st_target *t, int w, int h, int num_color, GLenum fmt, bool with_depth,
                      st_err *err) {
    memset(t, 0, sizeof *t);
    if (w < 1 || h < 1 || num_color < 0 || num_color > ST_TARGET_MAX_COLOR)
        return st_fail(err, ST_ERR_RUNTIME, "bad render target %dx%d x%d", w, h, num_color);
    t->width = w;
    t->height = h;
    t->num_color = num_color;
    t->color_format = fmt;
    glCreateFramebuffers(1, &t->fbo);
    GLenum bufs[ST_TARGET_MAX_COLOR];
    for (int i = 0; i < num_color; i++) {
        glCreateTextures(GL_TEXTURE_2D, 1, &t->color[i]);
        glTextureStorage2D(t->color[i], 1, fmt, w, h);
        glTextureParameteri(t->color[i], GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(t->color[i], GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(t->color[i], GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(t->color[i], GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glNamedFramebufferTexture(t->fbo, GL_COLOR_ATTACHMENT0 + i, t->color[i], 0);
        bufs[i] = GL_COLOR_ATTACHMENT0 + i;
        t->bytes += (size_t)w * h * st_format_bytes(fmt);
    }
    glNamedFramebufferDrawBuffers(t->fbo, num_color, bufs);
    if (with_depth) {
        glCreateTextures(GL_TEXTURE_2D, 1, &t->depth);
        glTextureStorage2D(t->depth, 1, GL_DEPTH_COMPONENT32F, w, h);
        glTextureParameteri(t->depth, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(t->depth, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glNamedFramebufferTexture(t->fbo, GL_DEPTH_ATTACHMENT, t->depth, 0);
        t->bytes += (size_t)w * h * 4;
    }
    t->type = GL_TEXTURE_2D;
    t->layers = t->levels = 1;
    g_bytes += t->bytes;
    GLenum st = glCheckNamedFramebufferStatus(t->fbo, GL_FRAMEBUFFER);
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        st_target_destroy(t);
        return st_fail(err, ST_ERR_RUNTIME, "framebuffer %dx%d incomplete (0x%x)", w, h, st);
    }
    return st_gl_check("render target", err);
}

void st_target_destroy(st_target *t) {
    if (t->fbo) glDeleteFramebuffers(1, &t->fbo);
    for (int i = 0; i < t->num_color; i++)
        if (t->color[i]) glDeleteTextures(1, &t->color[i]);
    if (t->depth) glDeleteTextures(1, &t->depth);
    g_bytes -= t->bytes;
    memset(t, 0, sizeof *t);
}

bool st_target_create_desc(st_target *t, const st_target_desc *d, int w, int h, st_err *err) {
    memset(t, 0, sizeof *t);
    GLenum type = d->type ? d->type : GL_TEXTURE_2D;
    int layers = d->layers > 0 ? d->layers : 1, levels = d->levels > 0 ? d->levels : 1;
    if (type == GL_TEXTURE_1D) h = 1;
    if (w < 1 || h < 1 || (type == GL_TEXTURE_CUBE_MAP_ARRAY && w != h))
        return st_fail(err, ST_ERR_RUNTIME, "bad render target %dx%d", w, h);
    t->width = w, t->height = h, t->num_color = 1, t->color_format = d->format;
    t->type = type, t->layers = layers, t->levels = levels;
    int faces = type == GL_TEXTURE_CUBE_MAP_ARRAY ? 6 * layers
                : type == GL_TEXTURE_2D_ARRAY     ? layers
                                                  : 1;
    glCreateTextures(type, 1, &t->color[0]);
    if (type == GL_TEXTURE_1D)
        glTextureStorage1D(t->color[0], levels, d->format, w);
    else if (type == GL_TEXTURE_2D)
        glTextureStorage2D(t->color[0], levels, d->format, w, h);
    else
        glTextureStorage3D(t->color[0], levels, d->format, w, h, faces);
    GLenum filter = d->filter ? d->filter : GL_LINEAR;
    GLenum min = levels == 1            ? filter
                 : filter == GL_NEAREST ? GL_NEAREST_MIPMAP_NEAREST
                                        : GL_LINEAR_MIPMAP_NEAREST;
    GLenum wrap = d->wrap ? d->wrap : d->border_zero ? GL_CLAMP_TO_BORDER : GL_CLAMP_TO_EDGE;
    glTextureParameteri(t->color[0], GL_TEXTURE_MIN_FILTER, (GLint)min);
    glTextureParameteri(t->color[0], GL_TEXTURE_MAG_FILTER, (GLint)filter);
    glTextureParameteri(t->color[0], GL_TEXTURE_WRAP_S, (GLint)wrap);
    glTextureParameteri(t->color[0], GL_TEXTURE_WRAP_T, (GLint)wrap);
    glTextureParameteri(t->color[0], GL_TEXTURE_WRAP_R, (GLint)wrap);
    glTextureParameterfv(t->color[0], GL_TEXTURE_BORDER_COLOR, (const float[4]){0, 0, 0, 0});
    for (int l = 0; l < levels; l++) {
        size_t lw = (size_t)(w >> l ? w >> l : 1), lh = (size_t)(h >> l ? h >> l : 1);
        t->bytes += lw * lh * (size_t)faces * st_format_bytes(d->format);
    }
    if (type != GL_TEXTURE_1D) { // 1D textures are lookup tables: no framebuffer
        glCreateFramebuffers(1, &t->fbo);
        if (type == GL_TEXTURE_2D)
            glNamedFramebufferTexture(t->fbo, GL_COLOR_ATTACHMENT0, t->color[0], 0);
        else
            glNamedFramebufferTextureLayer(t->fbo, GL_COLOR_ATTACHMENT0, t->color[0], 0, 0);
        if (d->depth) {
            glCreateTextures(GL_TEXTURE_2D, 1, &t->depth);
            glTextureStorage2D(t->depth, 1, GL_DEPTH_COMPONENT32F, w, h);
            glNamedFramebufferTexture(t->fbo, GL_DEPTH_ATTACHMENT, t->depth, 0);
            t->bytes += (size_t)w * h * 4;
        }
    }
    g_bytes += t->bytes;
    GLenum st =
        t->fbo ? glCheckNamedFramebufferStatus(t->fbo, GL_FRAMEBUFFER) : GL_FRAMEBUFFER_COMPLETE;
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        st_target_destroy(t);
        return st_fail(err, ST_ERR_RUNTIME, "framebuffer %dx%d (%s) incomplete (0x%x)", w, h,
                       st_format_name(d->format), st);
    }
    return st_gl_check("render target", err);
}

void st_target_bind_layer(const st_target *t, int layer) {
    glNamedFramebufferTextureLayer(t->fbo, GL_COLOR_ATTACHMENT0, t->color[0], 0, layer);
    st_target_bind(t);
}

void st_target_bind(const st_target *t) {
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, t->width, t->height);
}

bool st_target_read(const st_target *t, int index, float *rgba, st_err *err) {
    size_t row = (size_t)t->width * 4;
    float *tmp = malloc(row * t->height * sizeof(float));
    if (!tmp)
        return st_fail(err, ST_ERR_RUNTIME, "out of memory reading back %dx%d", t->width,
                       t->height);
    glGetTextureImage(t->color[index], 0, GL_RGBA, GL_FLOAT,
                      (GLsizei)(row * t->height * sizeof(float)), tmp);
    // GL's row 0 is the bottom; images are stored top row first.
    for (int j = 0; j < t->height; j++)
        memcpy(rgba + row * j, tmp + row * (t->height - 1 - j), row * sizeof(float));
    free(tmp);
    return st_gl_check("read back", err);
}

void st_hammersley(int n, float *xy) {
    for (int i = 0; i < n; i++) {
        uint32_t b = (uint32_t)i, r = 0;
        for (int k = 0; k < 32; k++, b >>= 1)
            r = (r << 1) | (b & 1);
        xy[2 * i] = (float)((double)i / n);
        xy[2 * i + 1] = (float)(r * 2.3283064365386963e-10);
    }
}

bool st_hammersley_upload(GLuint tex, int n, float *xy) {
    if (n < 1) return false;
    float *v = xy ? xy : malloc((size_t)n * 2 * sizeof *v);
    if (!v) return false;
    st_hammersley(n, v);
    glTextureSubImage1D(tex, 0, 0, n, GL_RG, GL_FLOAT, v);
    if (!xy) free(v);
    return true;
}

void st_draw_fullscreen(void) {
    if (!g_empty_vao) glCreateVertexArrays(1, &g_empty_vao);
    glBindVertexArray(g_empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}
