#include "st_gl.h"
#include <GLFW/glfw3.h>
#include <epoxy/egl.h>
#include <stdlib.h>
#include <string.h>

struct st_context {
    EGLDisplay dpy;
    EGLContext ctx;
    GLFWwindow *window;
};

static const char *egl_error_name(EGLint e) {
    switch (e) {
    case EGL_SUCCESS:
        return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
        return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ALLOC:
        return "EGL_BAD_ALLOC";
    case EGL_BAD_CONFIG:
        return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
        return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
        return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
        return "EGL_BAD_MATCH";
    case EGL_BAD_ATTRIBUTE:
        return "EGL_BAD_ATTRIBUTE";
    default:
        return "EGL error";
    }
}

// Headless contexts alive in this process. EGL displays are per process and
// eglTerminate ends every context of one, so it waits for the last (a host
// such as the Python module keeps one context while a bench makes its own).
static int g_live_headless;

static void release_display(EGLDisplay dpy) {
    if (g_live_headless == 0) eglTerminate(dpy);
}

// Tries one display: initialise, pick a config, make a 4.5 core context
// current without a surface. Returns false (display terminated) on failure.
static bool try_display(st_context *c, EGLDisplay dpy) {
    if (dpy == EGL_NO_DISPLAY) return false;
    EGLint major, minor;
    if (!eglInitialize(dpy, &major, &minor)) return false;
    if (!eglBindAPI(EGL_OPENGL_API)) goto fail;
    const EGLint cfg_attr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLConfig cfg;
    EGLint n = 0;
    // SURFACE_TYPE 0 is not accepted everywhere; fall back to pbuffer configs.
    if (!eglChooseConfig(dpy, cfg_attr, &cfg, 1, &n) || n < 1) {
        const EGLint pb_attr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
                                  EGL_PBUFFER_BIT, EGL_NONE};
        if (!eglChooseConfig(dpy, pb_attr, &cfg, 1, &n) || n < 1) goto fail;
    }
    const EGLint ctx_attr[] = {EGL_CONTEXT_MAJOR_VERSION,
                               4,
                               EGL_CONTEXT_MINOR_VERSION,
                               5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attr);
    if (ctx == EGL_NO_CONTEXT) goto fail;
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        eglDestroyContext(dpy, ctx);
        goto fail;
    }
    c->dpy = dpy;
    c->ctx = ctx;
    g_live_headless++;
    return true;
fail:
    release_display(dpy);
    return false;
}

st_context *st_context_create_headless(st_err *err) {
    st_context *c = calloc(1, sizeof *c);
    if (!c) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    bool ok = false;
    if (epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_device")) {
        PFNEGLQUERYDEVICESEXTPROC query =
            (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
        EGLDeviceEXT devs[8];
        EGLint ndev = 0;
        if (query && query(8, devs, &ndev)) {
            for (EGLint i = 0; i < ndev && !ok; i++)
                ok = try_display(c,
                                 eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL));
        }
    }
    if (!ok && epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless"))
        ok = try_display(
            c, eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL));
    if (!ok) ok = try_display(c, eglGetDisplay(EGL_DEFAULT_DISPLAY));
    if (!ok) {
        st_fail(err, ST_ERR_RUNTIME,
                "no OpenGL 4.5 core context through EGL (%s); install Mesa (libegl-mesa0, "
                "libgl1-mesa-dri) or a GPU driver",
                egl_error_name(eglGetError()));
        free(c);
        return NULL;
    }
    return c;
}

static void glfw_error(int code, const char *msg) {
    (void)code, (void)msg;
}

st_context *st_context_create_window(int width, int height, const char *title, int vsync,
                                     st_err *err) {
    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) {
        const char *d = NULL;
        glfwGetError(&d);
        st_fail(err, ST_ERR_RUNTIME, "cannot open a window: %s", d ? d : "glfwInit failed");
        return NULL;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    GLFWwindow *w = glfwCreateWindow(width, height, title, NULL, NULL);
    if (!w) {
        const char *d = NULL;
        glfwGetError(&d);
        st_fail(err, ST_ERR_RUNTIME, "cannot create an OpenGL 4.5 core window: %s",
                d ? d : "unknown");
        glfwTerminate();
        return NULL;
    }
    glfwMakeContextCurrent(w);
    glfwSwapInterval(vsync);
    st_context *c = calloc(1, sizeof *c);
    if (!c) {
        glfwDestroyWindow(w);
        glfwTerminate();
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    c->window = w;
    return c;
}

bool st_context_make_current(st_context *c, bool current, st_err *err) {
    if (c->window) {
        glfwMakeContextCurrent(current ? c->window : NULL);
        return true;
    }
    if (!eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, current ? c->ctx : EGL_NO_CONTEXT))
        return st_fail(err, ST_ERR_RUNTIME, "eglMakeCurrent failed: %s",
                       egl_error_name(eglGetError()));
    return true;
}

void st_context_destroy(st_context *c) {
    if (!c) return;
    if (c->window) {
        glfwDestroyWindow(c->window);
        glfwTerminate();
    } else {
        eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(c->dpy, c->ctx);
        g_live_headless--;
        release_display(c->dpy);
    }
    free(c);
}

void *st_context_window(st_context *c) {
    return c ? c->window : NULL;
}

const char *st_context_renderer(void) {
    const char *r = (const char *)glGetString(GL_RENDERER);
    return r ? r : "unknown";
}

static const char *gl_error_name(GLenum e) {
    switch (e) {
    case GL_INVALID_ENUM:
        return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
        return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
        return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
        return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
        return "GL_OUT_OF_MEMORY";
    default:
        return "GL error";
    }
}

bool st_gl_check_at(const char *what, const char *file, int line, st_err *err) {
    GLenum e = glGetError(), first = e;
    if (e == GL_NO_ERROR) return true;
    while (e != GL_NO_ERROR)
        e = glGetError();
    return st_fail(err, first == GL_OUT_OF_MEMORY ? ST_ERR_RUNTIME : ST_ERR_RUNTIME,
                   "%s:%d: %s: %s (0x%x)", file, line, what, gl_error_name(first), first);
}
