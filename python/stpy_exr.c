// strahl.read_exr() and strahl.write_exr(): EXR files to and from numpy
// arrays, with the standard-error channels `strahl reference` writes.
#include "stpy.h"
#include <string.h>

PyObject *stpy_read_exr(PyObject *self, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"path", NULL};
    PyObject *path;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O:read_exr", kwlist, &path)) return NULL;
    st_image img = {0}, se = {0};
    if (!stpy_image(path, "read_exr", &img, &se)) return NULL;
    PyObject *a = img.channels >= 3 ? stpy_array(&img, 0) : NULL;
    if (img.channels < 3) PyErr_SetString(stpy_error, "read_exr: the file has no R, G, B");
    PyObject *s = a && se.data ? stpy_array(&se, 0) : (Py_INCREF(Py_None), Py_None);
    st_image_free(&img);
    st_image_free(&se);
    return a && s ? Py_BuildValue("(NN)", a, s) : (Py_XDECREF(a), Py_XDECREF(s), NULL);
}

PyObject *stpy_write_exr(PyObject *self, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"path", "image", "stderr", NULL};
    PyObject *po, *io, *so = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|O:write_exr", kwlist, &po, &io, &so))
        return NULL;
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    st_image img = {0}, se = {0}, both = {0};
    char *path = NULL;
    st_err err = {0};
    bool ok = stpy_path(po, "path", &path) && stpy_image(io, "image", &img, NULL) &&
              (so == Py_None || stpy_image(so, "stderr", &se, NULL));
    bool done = false;
    if (ok && se.data && (se.width != img.width || se.height != img.height)) {
        PyErr_SetString(stpy_error, "write_exr: stderr is not the image's size");
    } else if (ok && se.data) { // the six channels `strahl reference` writes
        done = st_image_alloc(&both, img.width, img.height, 6, &err);
        for (size_t i = 0; done && i < (size_t)img.width * img.height; i++) {
            memcpy(both.data + 6 * i, img.data + 3 * i, 3 * sizeof(float));
            memcpy(both.data + 6 * i + 3, se.data + 3 * i, 3 * sizeof(float));
        }
        done = done && st_image_write_exr_named(path, &both, names, &err);
    } else if (ok) {
        done = st_image_write_exr(path, &img, &err);
    }
    if (ok && !done && !PyErr_Occurred()) stpy_raise(&err);
    free(path);
    st_image_free(&img), st_image_free(&se), st_image_free(&both);
    if (!done) return NULL;
    Py_RETURN_NONE;
}
