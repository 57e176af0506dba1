// strahl.bench(): the rows `strahl bench` writes (tools/cmd_bench.c,
// st_bench_rows), as a list of dicts keyed by the CSV's columns.
#define _DEFAULT_SOURCE // strsep, strtok_r
#include "cmd_shared.h"
#include "stpy.h"
#include <stdlib.h>
#include <string.h>

// One CSV field as int, float or str.
static PyObject *field(const char *s) {
    char *e;
    if (*s) {
        long long i = strtoll(s, &e, 10);
        if (!*e) return PyLong_FromLongLong(i);
        double d = strtod(s, &e);
        if (!*e) return PyFloat_FromDouble(d);
    }
    return PyUnicode_FromString(s);
}

// The CSV text (header first) as a list of dicts; text is modified.
static PyObject *rows_of(char *text) {
    char *keys[64], *save = NULL;
    int nkeys = 0;
    char *line = strtok_r(text, "\n", &save), *hdr = line;
    for (char *k = hdr ? strsep(&hdr, ",") : NULL; k && nkeys < 64; k = strsep(&hdr, ","))
        keys[nkeys++] = k;
    PyObject *list = PyList_New(0);
    while (list && (line = strtok_r(NULL, "\n", &save))) {
        PyObject *d = PyDict_New();
        char *f = line;
        for (int k = 0; d && k < nkeys && f; k++) {
            PyObject *v = field(strsep(&f, ","));
            if (!v || PyDict_SetItemString(d, keys[k], v) < 0) Py_CLEAR(d);
            Py_XDECREF(v);
        }
        if (!d || PyList_Append(list, d) < 0) Py_CLEAR(list);
        Py_XDECREF(d);
    }
    return list;
}

// --sweep "module.param=v1,v2,..." for each key of the sweep dict.
static bool sweep_args(stpy_strings *a, PyObject *sweep) {
    if (!PyDict_Check(sweep) || !PyDict_Size(sweep)) {
        PyErr_SetString(stpy_error, "sweep: expected {\"module.param\": [v1, v2, ...]}");
        return false;
    }
    PyObject *k, *v;
    Py_ssize_t pos = 0;
    while (PyDict_Next(sweep, &pos, &k, &v)) {
        const char *key = PyUnicode_Check(k) ? PyUnicode_AsUTF8(k) : NULL;
        PyObject *seq = key ? PySequence_Fast(v, "sweep: values are a list") : NULL;
        char arg[4096];
        size_t l = key ? (size_t)snprintf(arg, sizeof arg, "%s=", key) : 0;
        for (Py_ssize_t i = 0; seq && i < PySequence_Fast_GET_SIZE(seq) && l < sizeof arg; i++) {
            char val[256];
            if (!stpy_format_value(PySequence_Fast_GET_ITEM(seq, i), key, val, sizeof val)) break;
            l += (size_t)snprintf(arg + l, sizeof arg - l, "%s%s", i ? "," : "", val);
        }
        bool ok = seq && !PyErr_Occurred() && stpy_push(a, "sweep", "--sweep") &&
                  stpy_push(a, "sweep", arg);
        Py_XDECREF(seq);
        if (!ok) {
            if (!PyErr_Occurred()) PyErr_SetString(stpy_error, "sweep: keys are \"module.param\"");
            return false;
        }
    }
    return true;
}

// argv of `strahl bench` for the arguments.
static bool bench_argv(stpy_strings *a, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"scene",  "reference", "sweep",  "set",  "size", "filter",
                             "frames", "warmup",    "metric", "mode", NULL};
    PyObject *scene, *ref, *sweep, *sets = NULL, *size = NULL, *filter = NULL;
    long frames = 10, warmup = 2;
    const char *metric = "rmse", *mode = "recompute";
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OOO|$OOOllss:bench", kwlist, &scene, &ref, &sweep,
                                     &sets, &size, &filter, &frames, &warmup, &metric, &mode))
        return false;
    char *sp = NULL, *rp = NULL, num[64];
    stpy_strings s = {0};
    int w = 0, h = 0;
    bool ok = stpy_path(scene, "scene", &sp) && stpy_path(ref, "reference", &rp) &&
              stpy_push(a, "bench", "bench") && stpy_push(a, "bench", sp) &&
              stpy_push(a, "bench", "--reference") && stpy_push(a, "bench", rp) &&
              sweep_args(a, sweep) && stpy_sets(sets, &s) && stpy_size(size, &w, &h);
    for (int i = 0; ok && i < s.n; i++)
        ok = stpy_push(a, "set", "--set") && stpy_push(a, "set", s.s[i]);
    const char *opts[] = {"--frames", "--warmup", "--metric", "--mode", "--size", "--filter"};
    for (int i = 0; ok && i < 6; i++) {
        const char *v = num;
        if (i == 0) snprintf(num, sizeof num, "%ld", frames);
        if (i == 1) snprintf(num, sizeof num, "%ld", warmup);
        if (i == 2) v = metric;
        if (i == 3) v = mode;
        if (i == 4) snprintf(num, sizeof num, "%dx%d", w, h), v = w ? num : NULL;
        if (i == 5) v = filter && filter != Py_None ? PyUnicode_AsUTF8(filter) : NULL;
        if (i == 5 && filter && filter != Py_None && !v) ok = false;
        ok = ok && (!v || (stpy_push(a, "bench", opts[i]) && stpy_push(a, "bench", v)));
    }
    free(sp), free(rp);
    stpy_strings_free(&s);
    return ok;
}

PyObject *stpy_bench(PyObject *self, PyObject *args, PyObject *kw) {
    stpy_strings a = {0};
    if (!bench_argv(&a, args, kw)) {
        stpy_strings_free(&a);
        return NULL;
    }
    st_err err = {0};
    char *text = NULL;
    PyThreadState *ts = PyEval_SaveThread();
    if (stpy_gl_enter(&err)) {
        text = st_bench_rows(a.n, a.s, stpy_gl_context(), &err);
        stpy_gl_leave();
    }
    PyEval_RestoreThread(ts);
    PyObject *out = text ? rows_of(text) : stpy_raise(&err);
    free(text);
    stpy_strings_free(&a);
    return out;
}
