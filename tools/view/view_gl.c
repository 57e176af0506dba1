// GL side of strahl view: the display pass (HDR image -> window) and the
// overlay batch (rectangles and stb_easy_font text as coloured triangles,
// one streamed buffer, one draw call per frame). Shaders are inline: they
// belong to the viewer, not to the world, so hot reload leaves them alone.
#define _GNU_SOURCE
#include "view.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

static const char *fullscreen_vs = "#version 450 core\n"
                                   "void main() {\n"
                                   "    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);\n"
                                   "    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
                                   "}\n";

// Same encoding as st_image_write_png: radiance * 2^exposure, clamped, exact
// piecewise sRGB. The window and the world image may differ in size for a
// frame during a resize, so pixels are mapped, not assumed equal.
static const char *display_fs =
    "#version 450 core\n"
    "uniform sampler2D u_img;\n"
    "uniform float u_scale;\n"
    "uniform vec2 u_fb;\n"
    "uniform vec2 u_off;\n"
    "out vec4 o;\n"
    "float enc(float x) {\n"
    "    x = clamp(x, 0.0, 1.0);\n"
    "    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;\n"
    "}\n"
    "void main() {\n"
    "    ivec2 sz = textureSize(u_img, 0);\n"
    "    ivec2 p = ivec2((gl_FragCoord.xy - u_off) * vec2(sz) / u_fb);\n"
    "    vec3 c = texelFetch(u_img, clamp(p, ivec2(0), sz - 1), 0).rgb * u_scale;\n"
    "    if (any(isnan(c))) c = vec3(1.0, 0.0, 1.0);\n"
    "    o = vec4(enc(c.r), enc(c.g), enc(c.b), 1.0);\n"
    "}\n";

static const char *ui_vs = "#version 450 core\n"
                           "layout(location = 0) in vec2 a_pos;\n"
                           "layout(location = 1) in vec4 a_color;\n"
                           "uniform vec2 u_size;\n"
                           "out vec4 v_color;\n"
                           "void main() {\n"
                           "    v_color = a_color;\n"
                           "    gl_Position = vec4(a_pos.x / u_size.x * 2.0 - 1.0, 1.0 - a_pos.y / "
                           "u_size.y * 2.0, 0.0, 1.0);\n"
                           "}\n";

static const char *ui_fs = "#version 450 core\n"
                           "in vec4 v_color;\n"
                           "out vec4 o;\n"
                           "void main() { o = v_color; }\n";

// The viewer's own shaders are built from strings so a broken shader folder
// (hot reload) never takes the display down.
static GLuint program(const char *vs, const char *fs, const char *what, st_err *err) {
    char name[64];
    snprintf(name, sizeof name, "viewer %s", what);
    GLuint p = st_program_from_source(vs, fs, name, err);
    if (!p) err->kind = ST_ERR_RUNTIME;
    return p;
}

bool view_gl_init(view_gl *g, st_err *err) {
    g->display_prog = program(fullscreen_vs, display_fs, "display", err);
    if (!g->display_prog) return false;
    g->ui_prog = program(ui_vs, ui_fs, "overlay", err);
    if (!g->ui_prog) return false;
    g->d_img = glGetUniformLocation(g->display_prog, "u_img");
    g->d_scale = glGetUniformLocation(g->display_prog, "u_scale");
    g->d_fb = glGetUniformLocation(g->display_prog, "u_fb");
    g->d_off = glGetUniformLocation(g->display_prog, "u_off");
    g->ui_size = glGetUniformLocation(g->ui_prog, "u_size");
    glCreateVertexArrays(1, &g->empty_vao);
    glCreateVertexArrays(1, &g->ui_vao);
    glCreateBuffers(1, &g->ui_vbo);
    glVertexArrayVertexBuffer(g->ui_vao, 0, g->ui_vbo, 0, sizeof(view_vtx));
    glEnableVertexArrayAttrib(g->ui_vao, 0);
    glEnableVertexArrayAttrib(g->ui_vao, 1);
    glVertexArrayAttribFormat(g->ui_vao, 0, 2, GL_FLOAT, GL_FALSE, offsetof(view_vtx, x));
    glVertexArrayAttribFormat(g->ui_vao, 1, 4, GL_UNSIGNED_BYTE, GL_TRUE, offsetof(view_vtx, rgba));
    glVertexArrayAttribBinding(g->ui_vao, 0, 0);
    glVertexArrayAttribBinding(g->ui_vao, 1, 0);
    if (g->scale <= 0) g->scale = 1;
    return st_gl_check("viewer GL objects", err);
}

void view_gl_free(view_gl *g) {
    if (g->display_prog) glDeleteProgram(g->display_prog);
    if (g->ui_prog) glDeleteProgram(g->ui_prog);
    if (g->ui_vbo) glDeleteBuffers(1, &g->ui_vbo);
    if (g->ui_vao) glDeleteVertexArrays(1, &g->ui_vao);
    if (g->empty_vao) glDeleteVertexArrays(1, &g->empty_vao);
    free(g->v);
    memset(g, 0, sizeof *g);
}

void view_gl_display(view_gl *g, GLuint tex, int img_w, int img_h, int fb_w, int fb_h,
                     float exposure) {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fb_w, fb_h);
    // The largest rectangle of the image's aspect inside the window, centred.
    int w = fb_w, h = fb_h;
    if (img_w > 0 && img_h > 0 && (img_w != fb_w || img_h != fb_h)) {
        if ((double)fb_w * img_h > (double)fb_h * img_w)
            w = (int)((double)fb_h * img_w / img_h + 0.5);
        else
            h = (int)((double)fb_w * img_h / img_w + 0.5);
        if (w < 1) w = 1;
        if (h < 1) h = 1;
    }
    const int x0 = (fb_w - w) / 2, y0 = (fb_h - h) / 2;
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    if (!tex) return;
    glUseProgram(g->display_prog);
    glBindTextureUnit(0, tex);
    glUniform1i(g->d_img, 0);
    glUniform1f(g->d_scale, exp2f(exposure));
    glUniform2f(g->d_fb, (float)w, (float)h);
    glUniform2f(g->d_off, (float)x0, (float)y0);
    glViewport(x0, y0, w, h);
    glBindVertexArray(g->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glBindTextureUnit(0, 0);
    glViewport(0, 0, fb_w, fb_h); // the overlay covers the whole window
}

static view_vtx *reserve(view_gl *g, int n) {
    if (g->n + n > g->cap) {
        int cap = g->cap ? g->cap : 4096;
        while (g->n + n > cap)
            cap *= 2;
        view_vtx *nv = realloc(g->v, (size_t)cap * sizeof *nv);
        if (!nv) return NULL; // the overlay just loses this item
        g->v = nv;
        g->cap = cap;
    }
    view_vtx *out = g->v + g->n;
    g->n += n;
    return out;
}

static void quad(view_gl *g, float x0, float y0, float x1, float y1, uint32_t c) {
    view_vtx *q = reserve(g, 6);
    if (!q) return;
    q[0] = (view_vtx){x0, y0, c}, q[1] = (view_vtx){x1, y0, c}, q[2] = (view_vtx){x1, y1, c};
    q[3] = (view_vtx){x0, y0, c}, q[4] = (view_vtx){x1, y1, c}, q[5] = (view_vtx){x0, y1, c};
}

void view_ui_rect(view_gl *g, float x, float y, float w, float h, uint32_t rgba) {
    if (w > 0 && h > 0) quad(g, x, y, x + w, y + h, rgba);
}

void view_ui_patch_rect(view_gl *g, int first, float x, float y, float w, float h) {
    if (first < 0 || first + 6 > g->n) return;
    uint32_t c = g->v[first].rgba;
    int n = g->n;
    g->n = first;
    quad(g, x, y, x + w, y + h, c);
    g->n = n;
}

float view_ui_line(const view_gl *g) {
    return 11.0f * g->scale;
}

float view_ui_text_width(const view_gl *g, const char *s) {
    return (float)stb_easy_font_width((char *)s) * g->scale;
}

// stb_easy_font emits quads of 4 vertices (x, y, z, rgba) per segment; they
// become two triangles each, scaled around the text origin.
float view_ui_text(view_gl *g, float x, float y, const char *s, uint32_t rgba) {
    static char buf[64 * 1024];
    int nq = stb_easy_font_print(0, 0, (char *)s, NULL, buf, sizeof buf);
    const float k = g->scale;
    // Baseline offset: the font's glyphs start one unit below y.
    y += 1.5f * k;
    for (int i = 0; i < nq; i++) {
        const float *p = (const float *)(buf + (size_t)i * 64);
        float x0 = p[0], y0 = p[1], x1 = p[8], y1 = p[9]; // vertices 0 and 2 are opposite corners
        quad(g, x + x0 * k, y + y0 * k, x + x1 * k, y + y1 * k, rgba);
    }
    return view_ui_text_width(g, s);
}

void view_ui_flush(view_gl *g, int fb_w, int fb_h) {
    if (g->n) {
        size_t bytes = (size_t)g->n * sizeof(view_vtx);
        if (bytes > g->vbo_bytes) {
            glNamedBufferData(g->ui_vbo, (GLsizeiptr)bytes * 2, NULL, GL_STREAM_DRAW);
            g->vbo_bytes = bytes * 2;
        }
        glNamedBufferSubData(g->ui_vbo, 0, (GLsizeiptr)bytes, g->v);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, fb_w, fb_h);
        glEnable(GL_BLEND);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        glUseProgram(g->ui_prog);
        glUniform2f(g->ui_size, (float)fb_w, (float)fb_h);
        glBindVertexArray(g->ui_vao);
        glDrawArrays(GL_TRIANGLES, 0, g->n);
        glBindVertexArray(0);
        glDisable(GL_BLEND);
    }
    g->n = 0;
}

bool view_gl_capture(const char *path, int fb_w, int fb_h, st_err *err) {
    size_t row = (size_t)fb_w * 3;
    uint8_t *px = malloc(row * (size_t)fb_h), *flip = malloc(row * (size_t)fb_h);
    if (!px || !flip) {
        free(px), free(flip);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory capturing %dx%d", fb_w, fb_h);
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, fb_w, fb_h, GL_RGB, GL_UNSIGNED_BYTE, px);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    // GL's row 0 is the bottom.
    for (int j = 0; j < fb_h; j++)
        memcpy(flip + row * j, px + row * (size_t)(fb_h - 1 - j), row);
    bool ok = st_gl_check("window capture", err) && st_png_write8(path, flip, fb_w, fb_h, 3, err);
    free(px);
    free(flip);
    return ok;
}
