// strahl: OpenGL 4.5 core contexts (EGL headless, GLFW window) and GL error
// reporting. GL entry points come from libepoxy.
#ifndef ST_GL_H
#define ST_GL_H
#include "st_base.h"
#include <epoxy/gl.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_context st_context;

// Headless: EGL device platform (a real GPU), then Mesa surfaceless
// (llvmpipe without a GPU), then the default display. Needs no window system.
st_context *st_context_create_headless(st_err *err);
// A window with a 4.5 core context (GLFW); `vsync` 0/1.
st_context *st_context_create_window(int width, int height, const char *title, int vsync,
                                     st_err *err);
void st_context_destroy(st_context *ctx);
// Makes ctx current on the calling thread, or (current false) releases it
// so that another thread may take it (a host that calls from several
// threads, e.g. the Python module). A new context is current already.
bool st_context_make_current(st_context *ctx, bool current, st_err *err);
void *st_context_window(st_context *ctx); // GLFWwindow* or NULL when headless
const char *st_context_renderer(void);    // GL_RENDERER string

// Returns false and names `what` (with file:line of the caller) if glGetError
// reports anything since the last check.
bool st_gl_check_at(const char *what, const char *file, int line, st_err *err);
#define st_gl_check(what, err) st_gl_check_at((what), __FILE__, __LINE__, (err))

#ifdef __cplusplus
}
#endif
#endif
