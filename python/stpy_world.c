// strahl.World: one scene's world kept between calls, for loops and
// notebooks. Every GL call runs without the GIL on the shared context.
#include "cmd_common.h"
#include "st_still.h"
#include "stpy.h"
#include <math.h>
#include <string.h>

typedef struct world_obj {
    PyObject_HEAD st_scene scene; // lent to the world: lives as long as it
    bool has_scene;
    st_world *w;
} world_obj;

// What one call does on the world, without the GIL.
typedef bool (*world_op)(world_obj *o, void *arg, st_err *err);

static bool op_create(world_obj *o, void *arg, st_err *err);

// Runs op under the shared context with the GIL released; NULL (raised) on failure.
static bool run_op(world_obj *o, world_op op, void *arg) {
    if (!o->w && op != op_create) return PyErr_SetString(stpy_error, "the World is closed"), false;
    st_err err = {0};
    PyThreadState *ts = PyEval_SaveThread();
    bool ok = stpy_gl_enter(&err);
    if (ok) {
        ok = op(o, arg, &err);
        stpy_gl_leave();
    }
    PyEval_RestoreThread(ts);
    if (!ok) stpy_raise(&err);
    return ok;
}

static bool op_destroy(world_obj *o, void *arg, st_err *err) {
    st_world_destroy(o->w);
    o->w = NULL;
    return true;
}

static void world_close_now(world_obj *o) {
    if (o->w) run_op(o, op_destroy, NULL);
    if (o->has_scene) st_scene_free(&o->scene);
    o->has_scene = false;
}

static void world_dealloc(world_obj *o) {
    world_close_now(o);
    Py_TYPE(o)->tp_free((PyObject *)o);
}

typedef struct create_arg {
    stpy_strings on, off;
} create_arg;

static bool op_create(world_obj *o, void *arg, st_err *err) {
    create_arg *c = arg;
    st_still_opts still = {.frames = 1, .warmup = -1}; // converging frames: the still's defaults
    st_world_opts opts = st_still_world_opts(&o->scene, &still, true);
    o->w = st_world_create(&o->scene, &opts, err);
    return o->w && stpy_switch_modules(o->w, &c->on, &c->off, err);
}

static int world_init(world_obj *o, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"scene", "size", "filter", "set", "enable", "disable", NULL};
    PyObject *scene, *size = NULL, *filter = NULL, *sets = NULL, *on = NULL, *off = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$OOOOO:World", kwlist, &scene, &size, &filter,
                                     &sets, &on, &off))
        return -1;
    world_close_now(o);
    char *path = NULL;
    stpy_strings s = {0};
    create_arg c = {0};
    int width = 0, height = 0, rc = -1;
    st_pixel_filter f = ST_FILTER_BOX;
    bool has_filter = filter && filter != Py_None;
    st_err err = {0};
    if (stpy_path(scene, "scene", &path) && stpy_size(size, &width, &height) &&
        stpy_filter(filter, &f) && stpy_sets(sets, &s) && stpy_names(on, "enable", &c.on) &&
        stpy_names(off, "disable", &c.off)) {
        if (!st_load_scene_with(path, s.s, s.n, width, height, &o->scene, &err)) {
            stpy_raise(&err);
        } else {
            o->has_scene = true;
            if (has_filter) o->scene.filter = f;
            rc = run_op(o, op_create, &c) ? 0 : -1;
        }
    }
    if (rc) world_close_now(o);
    free(path);
    stpy_strings_free(&s), stpy_strings_free(&c.on), stpy_strings_free(&c.off);
    return rc;
}

typedef struct image_arg {
    st_image img;
    bool still;
} image_arg;

static bool op_image(world_obj *o, void *arg, st_err *err) {
    image_arg *a = arg;
    bool ok;
    if (a->still) {
        st_still_opts still = {.warmup = -1, .max_seconds = 600};
        st_still_settle(&still, 2000); // the frame cap of `strahl render`
        st_still_result res = {.frame_ms = calloc((size_t)still.frames, sizeof(float))};
        ok = res.frame_ms ? st_still_run(o->w, &still, &res, err)
                          : st_fail(err, ST_ERR_RUNTIME, "out of memory");
        free(res.frame_ms);
    } else {
        ok = st_world_frame(o->w, err);
    }
    return ok && st_world_read(o->w, &a->img, err) && stpy_finite(&a->img, err);
}

static PyObject *world_image(world_obj *o, bool still) {
    image_arg a = {.still = still};
    PyObject *out = run_op(o, op_image, &a) ? stpy_array(&a.img, 0) : NULL;
    st_image_free(&a.img);
    return out;
}

static PyObject *world_frame(world_obj *o, PyObject *unused) {
    return world_image(o, false);
}

static PyObject *world_still(world_obj *o, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"filter", NULL};
    PyObject *filter = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|$O:still", kwlist, &filter)) return NULL;
    st_pixel_filter f = o->w ? st_world_filter(o->w) : ST_FILTER_BOX;
    if (!stpy_filter(filter, &f)) return NULL;
    if (o->w && f != st_world_filter(o->w))
        return PyErr_Format(stpy_error,
                            "still(filter='%s'): this World renders with the %s filter (the "
                            "filter is chosen when it is created: World(scene, filter=...))",
                            st_filter_name(f), st_filter_name(st_world_filter(o->w)));
    return world_image(o, true);
}

typedef struct set_arg {
    char module[ST_NAME_MAX], param[ST_NAME_MAX];
    st_value value;
} set_arg;

static bool op_set(world_obj *o, void *arg, st_err *err) {
    set_arg *a = arg;
    const st_plugin *p = NULL;
    for (int i = 0; i < st_world_num_modules(o->w) && !p; i++)
        if (!strcmp(st_world_module(o->w, i).plugin->name, a->module))
            p = st_world_module(o->w, i).plugin;
    if (!p) return st_fail(err, ST_ERR_INPUT, "module '%s' is not loaded", a->module);
    int k = st_param_index(p, a->param);
    double v;
    if (k < 0)
        return st_fail(err, ST_ERR_INPUT, "module '%s' has no parameter '%s'", a->module, a->param);
    return st_param_from_value(p, k, &a->value, &v, err) &&
           st_world_set_param(o->w, a->module, a->param, v, err);
}

static PyObject *world_set(world_obj *o, PyObject *args) {
    const char *name;
    PyObject *value;
    if (!PyArg_ParseTuple(args, "sO:set", &name, &value)) return NULL;
    set_arg a = {0};
    const char *dot = strchr(name, '.');
    if (!dot || dot == name || !dot[1] || dot - name >= ST_NAME_MAX || strlen(dot) > ST_NAME_MAX)
        return PyErr_Format(stpy_error, "set %s: expected \"module.param\"", name);
    snprintf(a.module, sizeof a.module, "%.*s", (int)(dot - name), name);
    snprintf(a.param, sizeof a.param, "%s", dot + 1);
    if (!stpy_value(value, name, &a.value) || !run_op(o, op_set, &a)) return NULL;
    Py_RETURN_NONE;
}

typedef struct enable_arg {
    const char *name;
    bool on;
} enable_arg;

static bool op_enable(world_obj *o, void *arg, st_err *err) {
    enable_arg *a = arg;
    return a->on ? st_world_enable(o->w, a->name, true, err) : stpy_disable(o->w, a->name, err);
}

static PyObject *world_switch(world_obj *o, PyObject *args, bool on) {
    enable_arg a = {.on = on};
    if (!PyArg_ParseTuple(args, on ? "s:enable" : "s:disable", &a.name) ||
        !run_op(o, op_enable, &a))
        return NULL;
    Py_RETURN_NONE;
}
static PyObject *world_enable(world_obj *o, PyObject *args) {
    return world_switch(o, args, true);
}
static PyObject *world_disable(world_obj *o, PyObject *args) {
    return world_switch(o, args, false);
}

// A 3-vector argument; None keeps out as it is.
static bool vec3(PyObject *v, const char *what, float out[3]) {
    if (!v || v == Py_None) return true;
    PyObject *seq = PySequence_Check(v) ? PySequence_Fast(v, what) : NULL;
    bool ok = seq && PySequence_Fast_GET_SIZE(seq) == 3;
    double d[3] = {0, 0, 0};
    for (int k = 0; ok && k < 3; k++) {
        d[k] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, k));
        ok = !PyErr_Occurred() && isfinite(d[k]);
    }
    Py_XDECREF(seq);
    PyErr_Clear();
    if (!ok) return PyErr_Format(stpy_error, "%s: expected 3 finite numbers", what), false;
    for (int k = 0; k < 3; k++)
        out[k] = (float)d[k];
    return true;
}

typedef struct pose_arg {
    float pos[3], target[3], up[3], fov_y;
    int light;
} pose_arg;

static bool op_camera(world_obj *o, void *arg, st_err *err) {
    pose_arg *a = arg;
    st_world_camera(o->w)->fov_y = a->fov_y; // st_world_set_camera updates the matrices
    st_world_set_camera(o->w, a->pos, a->target, a->up);
    return true;
}

static PyObject *world_camera(world_obj *o, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"position", "target", "up", "fov_y", NULL};
    PyObject *p = NULL, *t = NULL, *u = NULL, *f = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|$OOOO:camera", kwlist, &p, &t, &u, &f))
        return NULL;
    if (!o->w) return PyErr_Format(stpy_error, "the World is closed");
    const st_camera *c = st_world_camera(o->w);
    pose_arg a = {.fov_y = c->fov_y};
    memcpy(a.pos, c->position, sizeof a.pos);
    memcpy(a.target, c->target, sizeof a.target);
    memcpy(a.up, c->up, sizeof a.up);
    double fov = f && f != Py_None ? PyFloat_AsDouble(f) : a.fov_y;
    if (PyErr_Occurred() || !(fov > 0 && fov < 180))
        return PyErr_Clear(), PyErr_Format(stpy_error, "fov_y: expected degrees in (0, 180)");
    a.fov_y = (float)fov;
    if (!vec3(p, "position", a.pos) || !vec3(t, "target", a.target) || !vec3(u, "up", a.up) ||
        !run_op(o, op_camera, &a))
        return NULL;
    Py_RETURN_NONE;
}

static bool op_light(world_obj *o, void *arg, st_err *err) {
    pose_arg *a = arg;
    return st_world_set_light(o->w, a->light, a->pos, a->target, err);
}

static PyObject *world_light(world_obj *o, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"i", "position", "intensity", NULL};
    PyObject *p = NULL, *in = NULL;
    pose_arg a = {0};
    if (!PyArg_ParseTupleAndKeywords(args, kw, "i|$OO:light", kwlist, &a.light, &p, &in))
        return NULL;
    if (!o->w) return PyErr_Format(stpy_error, "the World is closed");
    const st_scene *s = st_world_scene(o->w);
    if (a.light < 0 || a.light >= s->num_lights)
        return PyErr_Format(stpy_error, "light %d: the scene has %d", a.light, s->num_lights);
    memcpy(a.pos, s->lights[a.light].position, sizeof a.pos);
    memcpy(a.target, s->lights[a.light].intensity, sizeof a.target); // the intensity
    if (!vec3(p, "position", a.pos) || !vec3(in, "intensity", a.target) || !run_op(o, op_light, &a))
        return NULL;
    Py_RETURN_NONE;
}

static bool op_bytes(world_obj *o, void *arg, st_err *err) {
    *(size_t *)arg = st_world_memory_bytes(o->w);
    return true;
}

// One pass's statistics as a dict.
static PyObject *pass_dict(const st_pass_stats *s) {
    return Py_BuildValue("{s:s,s:s,s:I,s:I,s:I,s:d,s:d}", "module", s->module, "pass", s->pass,
                         "runs", s->runs, "skipped", s->skipped, "culled", s->culled, "gpu_ms",
                         st_median_f(s->gpu_ms, s->num_samples), "cpu_ms",
                         st_median_f(s->cpu_ms, s->num_samples));
}

static PyObject *world_stats(world_obj *o, PyObject *unused) {
    if (!o->w) return PyErr_Format(stpy_error, "the World is closed");
    PyObject *passes = PyList_New(0);
    for (int i = 0; passes && i < st_world_num_pass_stats(o->w); i++) {
        PyObject *d = pass_dict(st_world_pass_stats(o->w, i));
        if (!d || PyList_Append(passes, d) < 0) Py_CLEAR(passes);
        Py_XDECREF(d);
    }
    st_progress pr = {.converged = true};
    bool has = st_world_progress(o->w, &pr);
    bool done = false;
    uint32_t acc = st_world_accumulated(o->w, &done);
    // The memory table asks GL for tracked objects' sizes: under the context.
    size_t bytes = 0;
    if (!passes || !run_op(o, op_bytes, &bytes)) {
        Py_XDECREF(passes);
        return NULL;
    }
    return Py_BuildValue("{s:N,s:n,s:O,s:d,s:O,s:s,s:I,s:O}", "passes", passes, "gpu_bytes",
                         (Py_ssize_t)bytes, "converged", pr.converged ? Py_True : Py_False, "error",
                         has ? pr.error : 0.0, "progressive", has ? Py_True : Py_False,
                         "progress_info", pr.info, "accumulated", acc, "accumulation_done",
                         done ? Py_True : Py_False);
}

static PyObject *world_close(world_obj *o, PyObject *unused) {
    world_close_now(o);
    Py_RETURN_NONE;
}

static PyObject *world_enter(world_obj *o, PyObject *unused) {
    if (!o->w) return PyErr_Format(stpy_error, "the World is closed");
    Py_INCREF(o);
    return (PyObject *)o;
}

static PyObject *world_exit(world_obj *o, PyObject *args) {
    world_close_now(o);
    Py_RETURN_FALSE;
}

static PyMethodDef world_methods[] = {
    {"set", (PyCFunction)world_set, METH_VARARGS,
     "set(\"module.param\", value): change a loaded module's parameter (range-checked)"},
    {"enable", (PyCFunction)world_enable, METH_VARARGS, "enable(name): load a module"},
    {"disable", (PyCFunction)world_disable, METH_VARARGS, "disable(name): unload a module"},
    {"camera", (PyCFunction)(void (*)(void))world_camera, METH_VARARGS | METH_KEYWORDS,
     "camera(position=, target=, up=, fov_y=): move the camera (omitted: unchanged)"},
    {"light", (PyCFunction)(void (*)(void))world_light, METH_VARARGS | METH_KEYWORDS,
     "light(i, position=, intensity=): move light i or change its intensity"},
    {"frame", (PyCFunction)world_frame, METH_NOARGS,
     "frame() -> ndarray: render one frame; the image (box filter: the mean so far)"},
    {"still", (PyCFunction)(void (*)(void))world_still, METH_VARARGS | METH_KEYWORDS,
     "still(filter=None) -> ndarray: frames until converged, as strahl render"},
    {"stats", (PyCFunction)world_stats, METH_NOARGS,
     "stats() -> dict: per-pass runs and median GPU/CPU ms, GPU bytes, estimated error"},
    {"close", (PyCFunction)world_close, METH_NOARGS, "close(): free the world's GPU resources"},
    {"__enter__", (PyCFunction)world_enter, METH_NOARGS, NULL},
    {"__exit__", (PyCFunction)world_exit, METH_VARARGS, NULL},
    {NULL, NULL, 0, NULL}};

PyTypeObject stpy_world_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "strahl.World",
    .tp_basicsize = sizeof(world_obj),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "World(scene, size=None, filter=None, set=None, enable=None, disable=None): a "
              "scene's world kept between frames",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)world_init,
    .tp_dealloc = (destructor)world_dealloc,
    .tp_methods = world_methods,
};
