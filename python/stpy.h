// The `strahl` Python module (python/): what its files share. Errors become
// strahl.Error (bad input, a ValueError) or strahl.RenderError (runtime and
// GPU failures, a RuntimeError) with the command line's one-line message.
// Every call that touches GL releases the GIL and runs under one lock on
// the module's one headless context (EGL contexts of one display share its
// fate, so Worlds share the context rather than own one each).
#ifndef STPY_H
#define STPY_H
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include "st_gl.h"
#include "st_image.h"
#include "st_scene.h"
#include "st_world.h"

#define STPY_MAX_NAMES 128

extern PyObject *stpy_error, *stpy_render_error;
extern PyTypeObject stpy_world_type;

// Raises the exception for err's kind; returns NULL.
PyObject *stpy_raise(const st_err *err);
// Takes the lock and makes the shared context current (creating it on first
// use); call with the GIL released. stpy_gl_leave undoes it.
bool stpy_gl_enter(st_err *err);
void stpy_gl_leave(void);
// The shared context (between enter and leave).
st_context *stpy_gl_context(void);

// Argument conversion; each sets a Python exception and returns false on
// bad input.
//
// Strings that outlive the call: a list of owned C strings.
typedef struct stpy_strings {
    char *s[STPY_MAX_NAMES];
    int n;
} stpy_strings;
void stpy_strings_free(stpy_strings *l);
bool stpy_push(stpy_strings *l, const char *what, const char *s);
// A path (str or os.PathLike) as an owned string.
bool stpy_path(PyObject *o, const char *what, char **out);
// size=(w, h), 1..16384 each; None leaves *w, *h alone.
bool stpy_size(PyObject *o, int *w, int *h);
// set={"module.param": value} as "module.param=value" assignments (bools
// true/false, numbers exactly, strings as they are).
bool stpy_sets(PyObject *o, stpy_strings *out);
// A value as --set spells it; false (exception set) for other types.
bool stpy_format_value(PyObject *v, const char *key, char *out, size_t n);
// A sequence of names (enable=, disable=); a lone string is one name.
bool stpy_names(PyObject *o, const char *what, stpy_strings *out);
// A parameter value as the scene file would hold it.
bool stpy_value(PyObject *o, const char *what, st_value *out);
// filter="box"|"point"; None leaves *out alone.
bool stpy_filter(PyObject *o, st_pixel_filter *out);

// What render and World share (stpy_render.c): enable= and disable= on a
// world (disabling a module that is not loaded is an error), and the
// command line's refusal of non-finite images.
bool stpy_switch_modules(st_world *w, const stpy_strings *on, const stpy_strings *off, st_err *err);
bool stpy_disable(st_world *w, const char *module, st_err *err);
bool stpy_finite(const st_image *img, st_err *err);

// Channels [c0, c0 + 3) of img as a new float32 (H, W, 3) array.
PyObject *stpy_array(const st_image *img, int c0);
// An (H, W, 3) array-like (float32 after conversion) or an EXR path as an
// st_image (3 channels); *se gets the file's standard-error channels when
// se is not NULL (empty for an array).
bool stpy_image(PyObject *o, const char *what, st_image *img, st_image *se);

PyObject *stpy_render(PyObject *self, PyObject *args, PyObject *kw);
PyObject *stpy_reference(PyObject *self, PyObject *args, PyObject *kw);
PyObject *stpy_compare(PyObject *self, PyObject *args, PyObject *kw);
PyObject *stpy_modules(PyObject *self, PyObject *unused);
PyObject *stpy_bench(PyObject *self, PyObject *args, PyObject *kw);
PyObject *stpy_read_exr(PyObject *self, PyObject *args, PyObject *kw);
PyObject *stpy_write_exr(PyObject *self, PyObject *args, PyObject *kw);

#endif
