// strahl.render(), strahl.reference() and strahl.compare(): the commands'
// work (tools/st_still.c, tools/reference, st_image_compare_noisy) on arrays.
#include "cmd_common.h"
#include "reference/ref.h"
#include "st_still.h"
#include "stpy.h"
#include <string.h>

bool stpy_disable(st_world *w, const char *module, st_err *err) {
    // A name that is not loaded is a mistake (a typo would go unnoticed).
    if (!st_world_has_module(w, module))
        return st_fail(err, ST_ERR_INPUT, "disable %s: module '%s' is not loaded", module, module);
    return st_world_enable(w, module, false, err);
}

bool stpy_switch_modules(st_world *w, const stpy_strings *on, const stpy_strings *off,
                         st_err *err) {
    for (int i = 0; i < on->n; i++)
        if (!st_world_enable(w, on->s[i], true, err)) return false;
    for (int i = 0; i < off->n; i++)
        if (!stpy_disable(w, off->s[i], err)) return false;
    return true;
}

bool stpy_finite(const st_image *img, st_err *err) {
    size_t bad = st_image_count_nonfinite(img);
    return !bad || st_fail(err, ST_ERR_RUNTIME, "%zu non-finite values in the rendered image", bad);
}

typedef struct render_req {
    char *scene;
    stpy_strings sets, enable, disable;
    int width, height;
    bool has_filter;
    st_pixel_filter filter;
    st_still_opts still;
} render_req;

// The still of `strahl render` (without the GIL).
static bool render_still(const render_req *q, st_image *img, st_err *err) {
    st_scene scene = {0};
    if (!st_load_scene_with(q->scene, (char **)q->sets.s, q->sets.n, q->width, q->height, &scene,
                            err))
        return false;
    if (q->has_filter) scene.filter = q->filter;
    st_still_result res = {.frame_ms = calloc((size_t)q->still.frames, sizeof(float))};
    bool ok = res.frame_ms ? stpy_gl_enter(err) : st_fail(err, ST_ERR_RUNTIME, "out of memory");
    if (ok) {
        st_world_opts opts = st_still_world_opts(&scene, &q->still, false);
        st_world *w = st_world_create(&scene, &opts, err);
        ok = w && stpy_switch_modules(w, &q->enable, &q->disable, err) &&
             st_still_run(w, &q->still, &res, err) && st_world_read(w, img, err) &&
             stpy_finite(img, err);
        st_world_destroy(w);
        stpy_gl_leave();
    }
    free(res.frame_ms);
    st_scene_free(&scene);
    return ok;
}

static bool render_args(render_req *q, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"scene", "size", "filter", "set", "enable", "disable", "frames", NULL};
    PyObject *scene, *size = NULL, *filter = NULL, *sets = NULL, *on = NULL, *off = NULL,
                     *frames = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$OOOOOO:render", kwlist, &scene, &size, &filter,
                                     &sets, &on, &off, &frames))
        return false;
    q->has_filter = filter && filter != Py_None;
    if (!stpy_path(scene, "scene", &q->scene) || !stpy_size(size, &q->width, &q->height) ||
        !stpy_filter(filter, &q->filter) || !stpy_sets(sets, &q->sets) ||
        !stpy_names(on, "enable", &q->enable) || !stpy_names(off, "disable", &q->disable))
        return false;
    q->still = (st_still_opts){.warmup = -1, .max_seconds = 600};
    if (frames != Py_None) {
        q->still.frames = PyLong_Check(frames) ? PyLong_AsLong(frames) : -1;
        if (q->still.frames < 1 || q->still.frames > 100000) {
            PyErr_Clear();
            PyErr_SetString(stpy_error, "frames: expected 1..100000 (or None: until converged)");
            return false;
        }
        q->still.frames_given = true;
    }
    st_still_settle(&q->still, 2000); // the frame cap of `strahl render`
    return true;
}

PyObject *stpy_render(PyObject *self, PyObject *args, PyObject *kw) {
    render_req q = {0};
    st_image img = {0};
    st_err err = {0};
    bool ok = render_args(&q, args, kw), done = false;
    if (ok) {
        PyThreadState *ts = PyEval_SaveThread();
        done = render_still(&q, &img, &err);
        PyEval_RestoreThread(ts);
    }
    PyObject *out = !ok ? NULL : done ? stpy_array(&img, 0) : stpy_raise(&err);
    st_image_free(&img);
    free(q.scene);
    stpy_strings_free(&q.sets), stpy_strings_free(&q.enable), stpy_strings_free(&q.disable);
    return out;
}
