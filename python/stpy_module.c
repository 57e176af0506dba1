// The `strahl` Python module: its exceptions, the shared GL context and its
// lock and strahl.modules(); the rest is in stpy_*.c.
#include "cmd_shared.h"
#include "st_gl.h"
#include "st_module.h"
#include "stpy.h"
#include <pythread.h>
#include <string.h>

PyObject *stpy_error, *stpy_render_error;

static PyThread_type_lock gl_lock;
static st_context *gl_ctx;

int stpy_gl_init(void);
int stpy_gl_init(void) {
    gl_lock = PyThread_allocate_lock();
    return gl_lock ? 0 : -1;
}

PyObject *stpy_raise(const st_err *err) {
    PyErr_SetString(err->kind == ST_ERR_INPUT ? stpy_error : stpy_render_error,
                    err->msg[0] ? err->msg : "failed");
    return NULL;
}

bool stpy_gl_enter(st_err *err) {
    PyThread_acquire_lock(gl_lock, WAIT_LOCK);
    // The context lives as long as the process: destroying it would end
    // every World's (they share the EGL display).
    if (!gl_ctx && !(gl_ctx = st_context_create_headless(err))) {
        PyThread_release_lock(gl_lock);
        return false;
    }
    if (!st_context_make_current(gl_ctx, true, err)) {
        PyThread_release_lock(gl_lock);
        return false;
    }
    return true;
}

st_context *stpy_gl_context(void) {
    return gl_ctx;
}

void stpy_gl_leave(void) {
    // Released, so the next call may come from another thread.
    st_context_make_current(gl_ctx, false, NULL);
    PyThread_release_lock(gl_lock);
}

// One parameter descriptor as a dict.
static PyObject *param_dict(const st_param_def *d) {
    char def[64];
    st_param_format(d, d->def, def, sizeof def);
    PyObject *dflt = d->type == ST_PARAM_ENUM   ? PyUnicode_FromString(def)
                     : d->type == ST_PARAM_BOOL ? PyBool_FromLong(d->def != 0)
                     : d->type == ST_PARAM_INT  ? PyLong_FromDouble(d->def)
                                                : PyFloat_FromDouble(d->def);
    PyObject *range = Py_None, *choices = Py_None;
    Py_INCREF(Py_None), Py_INCREF(Py_None);
    if (d->type == ST_PARAM_FLOAT || d->type == ST_PARAM_INT) {
        Py_DECREF(range);
        range = Py_BuildValue("(dd)", d->min, d->max);
    }
    if (d->type == ST_PARAM_ENUM) {
        Py_DECREF(choices);
        choices = PyList_New(0);
        for (int k = 0; choices && k < st_param_num_choices(d); k++) {
            char name[ST_NAME_MAX];
            st_param_choice(d, k, name, sizeof name);
            PyObject *s = PyUnicode_FromString(name);
            if (!s || PyList_Append(choices, s) < 0) Py_CLEAR(choices);
            Py_XDECREF(s);
        }
    }
    if (!dflt || !range || !choices) {
        Py_XDECREF(dflt), Py_XDECREF(range), Py_XDECREF(choices);
        return NULL;
    }
    return Py_BuildValue("{s:s,s:s,s:N,s:N,s:N,s:s}", "name", d->name, "type",
                         st_param_type_name(d->type), "default", dflt, "range", range, "choices",
                         choices, "help", d->help ? d->help : "");
}

// One plugin's descriptor as a dict.
static PyObject *plugin_dict(const st_plugin *p) {
    PyObject *lights = PyList_New(0), *params = PyList_New(0);
    for (int t = 0; lights && t < ST_LIGHT_TYPE_COUNT; t++) {
        if (!(st_plugin_lights(p) & ST_LIGHT_BIT(t))) continue;
        PyObject *s = PyUnicode_FromString(st_light_type_name(t));
        if (!s || PyList_Append(lights, s) < 0) Py_CLEAR(lights);
        Py_XDECREF(s);
    }
    for (int k = 0; params && k < p->num_params; k++) {
        PyObject *d = param_dict(&p->params[k]);
        if (!d || PyList_Append(params, d) < 0) Py_CLEAR(params);
        Py_XDECREF(d);
    }
    if (!lights || !params) {
        Py_XDECREF(lights), Py_XDECREF(params);
        return NULL;
    }
    char abi[32];
    snprintf(abi, sizeof abi, "%u.%u", p->abi_major, p->abi_minor);
    return Py_BuildValue("{s:s,s:s,s:s,s:s,s:s,s:N,s:N}", "name", p->name, "description",
                         p->description ? p->description : "", "abi", abi, "requires",
                         p->requires ? p->requires : "", "provides", p->provides ? p->provides : "",
                         "lights", lights, "params", params);
}

PyObject *stpy_modules(PyObject *self, PyObject *unused) {
    char names[64][ST_NAME_MAX];
    int n = st_plugin_list(names, 64);
    PyObject *list = PyList_New(0);
    for (int i = 0; list && i < n; i++) {
        st_err err = {0};
        st_plugin_lib *lib = st_plugin_open(names[i], &err);
        if (!lib) {
            Py_DECREF(list);
            return stpy_raise(&err);
        }
        PyObject *d = plugin_dict(st_plugin_desc(lib));
        st_plugin_close(lib);
        if (!d || PyList_Append(list, d) < 0) Py_CLEAR(list);
        Py_XDECREF(d);
    }
    return list;
}
