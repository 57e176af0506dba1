// Python values to strahl's (stpy.h): paths, sizes, --set assignments, names,
// parameter values, and images to and from numpy arrays.
#include "stpy.h"
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <string.h>

// Imports numpy; where the interpreter has none of its own (a pyenv python3
// of the same version beside Debian's), the numpy the module was compiled
// against (STPY_NUMPY_SITE, appended to sys.path: the interpreter's own
// packages keep precedence).
static int import_numpy(void) {
    PyObject *np = PyImport_ImportModule("numpy");
    if (np || !PyErr_ExceptionMatches(PyExc_ImportError)) {
        Py_XDECREF(np);
        return np ? 0 : -1;
    }
    PyErr_Clear();
    PyObject *path = PySys_GetObject("path"), *site = PyUnicode_FromString(STPY_NUMPY_SITE);
    int rc = path && site ? PyList_Append(path, site) : -1;
    Py_XDECREF(site);
    if (rc < 0) return -1;
    np = PyImport_ImportModule("numpy");
    Py_XDECREF(np);
    return np ? 0 : -1;
}

int stpy_numpy_init(void);
int stpy_numpy_init(void) {
    if (import_numpy() < 0) return -1;
    import_array1(-1);
    return 0;
}

void stpy_strings_free(stpy_strings *l) {
    for (int i = 0; i < l->n; i++)
        free(l->s[i]);
    l->n = 0;
}

bool stpy_push(stpy_strings *l, const char *what, const char *s) {
    if (l->n == STPY_MAX_NAMES) {
        PyErr_Format(stpy_error, "%s: at most %d entries", what, STPY_MAX_NAMES);
        return false;
    }
    if (!(l->s[l->n] = strdup(s))) return PyErr_NoMemory(), false;
    l->n++;
    return true;
}

bool stpy_path(PyObject *o, const char *what, char **out) {
    PyObject *b = NULL;
    if (!PyUnicode_FSConverter(o, &b)) {
        PyErr_Format(PyExc_TypeError, "%s: expected a path (str or os.PathLike)", what);
        return false;
    }
    *out = strdup(PyBytes_AS_STRING(b));
    Py_DECREF(b);
    return *out ? true : (PyErr_NoMemory(), false);
}

bool stpy_size(PyObject *o, int *w, int *h) {
    if (!o || o == Py_None) return true;
    long v[2] = {0, 0};
    PyObject *seq = PySequence_Check(o) ? PySequence_Fast(o, "size") : NULL;
    bool ok = seq && PySequence_Fast_GET_SIZE(seq) == 2;
    for (int k = 0; ok && k < 2; k++) {
        PyObject *x = PySequence_Fast_GET_ITEM(seq, k);
        ok = PyLong_Check(x) && !PyBool_Check(x);
        if (ok) v[k] = PyLong_AsLong(x);
        ok = ok && !PyErr_Occurred() && v[k] >= 1 && v[k] <= 16384;
    }
    Py_XDECREF(seq);
    PyErr_Clear();
    if (!ok) {
        PyObject *r = PyObject_Repr(o);
        PyErr_Format(stpy_error, "size %s: expected (width, height), 1..16384 each",
                     r ? PyUnicode_AsUTF8(r) : "?");
        Py_XDECREF(r);
        return false;
    }
    *w = (int)v[0], *h = (int)v[1];
    return true;
}

bool stpy_format_value(PyObject *v, const char *key, char *out, size_t n) {
    if (PyBool_Check(v)) {
        snprintf(out, n, "%s", v == Py_True ? "true" : "false");
    } else if (PyLong_Check(v)) {
        long long x = PyLong_AsLongLong(v);
        if (x == -1 && PyErr_Occurred()) return false;
        snprintf(out, n, "%lld", x);
    } else if (PyFloat_Check(v)) {
        snprintf(out, n, "%.17g", PyFloat_AS_DOUBLE(v)); // round-trips exactly
    } else if (PyUnicode_Check(v)) {
        const char *s = PyUnicode_AsUTF8(v);
        if (!s) return false;
        snprintf(out, n, "%s", s);
    } else {
        PyErr_Format(stpy_error, "set %s: expected a bool, number or string, not %s", key,
                     Py_TYPE(v)->tp_name);
        return false;
    }
    return true;
}

bool stpy_sets(PyObject *o, stpy_strings *out) {
    if (!o || o == Py_None) return true;
    if (!PyDict_Check(o)) {
        PyErr_SetString(PyExc_TypeError, "set: expected a dict {\"module.param\": value}");
        return false;
    }
    PyObject *k, *v;
    Py_ssize_t pos = 0;
    while (PyDict_Next(o, &pos, &k, &v)) {
        const char *key = PyUnicode_Check(k) ? PyUnicode_AsUTF8(k) : NULL;
        if (!key) {
            PyErr_SetString(PyExc_TypeError, "set: keys are \"module.param\" strings");
            return false;
        }
        char val[256], assign[512];
        if (!stpy_format_value(v, key, val, sizeof val)) return false;
        snprintf(assign, sizeof assign, "%s=%s", key, val);
        if (!stpy_push(out, "set", assign)) return false;
    }
    return true;
}

bool stpy_names(PyObject *o, const char *what, stpy_strings *out) {
    if (!o || o == Py_None) return true;
    if (PyUnicode_Check(o)) return stpy_push(out, what, PyUnicode_AsUTF8(o));
    PyObject *seq = PySequence_Fast(o, "expected a list of module names");
    if (!seq) return false;
    bool ok = true;
    for (Py_ssize_t i = 0; ok && i < PySequence_Fast_GET_SIZE(seq); i++) {
        PyObject *x = PySequence_Fast_GET_ITEM(seq, i);
        const char *s = PyUnicode_Check(x) ? PyUnicode_AsUTF8(x) : NULL;
        if (!s) PyErr_Format(PyExc_TypeError, "%s: expected module names (str)", what);
        ok = s && stpy_push(out, what, s);
    }
    Py_DECREF(seq);
    return ok;
}

bool stpy_value(PyObject *o, const char *what, st_value *out) {
    memset(out, 0, sizeof *out);
    if (PyBool_Check(o)) {
        out->type = ST_VALUE_BOOL, out->number = o == Py_True;
    } else if (PyLong_Check(o) || PyFloat_Check(o)) {
        out->type = ST_VALUE_NUMBER, out->number = PyFloat_AsDouble(o);
        if (PyErr_Occurred()) return false;
    } else if (PyUnicode_Check(o)) {
        out->type = ST_VALUE_STRING;
        snprintf(out->str, sizeof out->str, "%s", PyUnicode_AsUTF8(o));
    } else {
        PyErr_Format(stpy_error, "%s: expected a bool, number or string, not %s", what,
                     Py_TYPE(o)->tp_name);
        return false;
    }
    return true;
}

bool stpy_filter(PyObject *o, st_pixel_filter *out) {
    if (!o || o == Py_None) return true;
    const char *s = PyUnicode_Check(o) ? PyUnicode_AsUTF8(o) : NULL;
    if (s && st_filter_parse(s, out)) return true;
    PyObject *r = PyObject_Repr(o);
    PyErr_Format(stpy_error, "filter %s: expected box or point", r ? PyUnicode_AsUTF8(r) : "?");
    Py_XDECREF(r);
    return false;
}

PyObject *stpy_array(const st_image *img, int c0) {
    npy_intp dims[3] = {img->height, img->width, 3};
    PyObject *a = PyArray_SimpleNew(3, dims, NPY_FLOAT32);
    if (!a) return NULL;
    float *dst = PyArray_DATA((PyArrayObject *)a);
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++)
        memcpy(dst + 3 * i, img->data + i * img->channels + c0, 3 * sizeof(float));
    return a;
}

// An (H, W, 3) array-like as a 3-channel image.
static bool image_of_array(PyObject *o, const char *what, st_image *img) {
    PyArrayObject *a = (PyArrayObject *)PyArray_FROMANY(
        o, NPY_FLOAT32, 3, 3, NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED | NPY_ARRAY_FORCECAST);
    if (!a) {
        PyErr_Clear();
        PyErr_Format(stpy_error, "%s: expected an EXR path or an (H, W, 3) float array", what);
        return false;
    }
    npy_intp *d = PyArray_DIMS(a);
    st_err err = {0};
    bool ok = d[2] == 3 && d[0] >= 1 && d[1] >= 1 && d[0] <= 65536 && d[1] <= 65536;
    if (!ok)
        PyErr_Format(stpy_error, "%s: expected an (H, W, 3) array, got (%zd, %zd, %zd)", what,
                     (Py_ssize_t)d[0], (Py_ssize_t)d[1], (Py_ssize_t)d[2]);
    else if (!(ok = st_image_alloc(img, (int)d[1], (int)d[0], 3, &err)))
        stpy_raise(&err);
    else
        memcpy(img->data, PyArray_DATA(a), (size_t)d[0] * d[1] * 3 * sizeof(float));
    Py_DECREF(a);
    return ok;
}

bool stpy_image(PyObject *o, const char *what, st_image *img, st_image *se) {
    if (!PyUnicode_Check(o) && !PyBytes_Check(o) && !PyObject_HasAttrString(o, "__fspath__"))
        return image_of_array(o, what, img);
    char *path = NULL;
    if (!stpy_path(o, what, &path)) return false;
    st_err err = {0};
    bool ok =
        st_image_read_exr(path, img, &err) && (!se || st_image_read_exr_stderr(path, se, &err));
    free(path);
    if (!ok) stpy_raise(&err);
    return ok;
}
