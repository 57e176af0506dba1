// strahl.reference() (tools/reference, as `strahl reference`) and
// strahl.compare() (st_image_compare_noisy, as `strahl compare`).
#include "cmd_common.h"
#include "reference/ref.h"
#include "stpy.h"
#include <math.h>
#include <string.h>

// Index of s in names (n of them), or -1 with strahl.Error set.
static int choice(const char *what, const char *s, const char *const *names, int n,
                  const char *expected) {
    for (int i = 0; s && i < n; i++)
        if (!strcmp(s, names[i])) return i;
    PyErr_Format(stpy_error, "%s %s: expected %s", what, s ? s : "?", expected);
    return -1;
}

static bool in_range(const char *what, long long v, long long lo, long long hi) {
    if (v >= lo && v <= hi) return true;
    PyErr_Format(stpy_error, "%s %lld: expected %lld..%lld", what, v, lo, hi);
    return false;
}

typedef struct ref_req {
    char *scene;
    stpy_strings sets;
    int width, height;
    bool has_filter;
    st_pixel_filter filter;
    st_ref_options o;
} ref_req;

static bool reference_args(ref_req *q, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"scene",      "size",    "spp", "bounces", "seed",
                             "aov",        "filter",  "set", "steps",   "estimator",
                             "visibility", "threads", NULL};
    PyObject *scene, *size = NULL, *filter = NULL, *sets = NULL;
    const char *aov = "combined", *est = "area";
    long long spp = 64, bounces = 1, steps = 256, threads = 0;
    unsigned long long seed = 0;
    int vis = 1;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$OLLKsOOLspL:reference", kwlist, &scene, &size,
                                     &spp, &bounces, &seed, &aov, &filter, &sets, &steps, &est,
                                     &vis, &threads))
        return false;
    static const char *const aovs[] = {"combined", "direct", "indirect", "inscatter"};
    static const char *const ests[] = {"area", "thesis"};
    int a = choice("aov", aov, aovs, 4, "combined, direct, indirect or inscatter");
    int e = a < 0 ? -1 : choice("estimator", est, ests, 2, "area or thesis");
    q->has_filter = filter && filter != Py_None;
    if (e < 0 || !in_range("spp", spp, 1, 10000000) || !in_range("bounces", bounces, 0, 16) ||
        !in_range("steps", steps, 1, 1000000) || !in_range("threads", threads, 0, 256) ||
        !stpy_path(scene, "scene", &q->scene) || !stpy_size(size, &q->width, &q->height) ||
        !stpy_filter(filter, &q->filter) || !stpy_sets(sets, &q->sets))
        return false;
    q->o = (st_ref_options){.spp = (int)spp,
                            .aov = (st_ref_aov)a,
                            .seed = seed,
                            .bounces = (int)bounces,
                            .no_visibility = !vis,
                            .estimator = (st_ref_estimator)e,
                            .march_steps = (int)steps,
                            .threads = (int)threads};
    return true;
}

// As `strahl reference` (without the GIL): --set is checked, the filter is
// the scene's unless given.
static bool reference_c(ref_req *q, st_image *img, st_err *err) {
    st_scene scene = {0};
    if (!st_load_scene_with(q->scene, q->sets.s, q->sets.n, q->width, q->height, &scene, err))
        return false;
    q->o.filter = q->has_filter ? q->filter : scene.filter;
    bool ok = st_ref_render(&scene, &q->o, img, err);
    st_scene_free(&scene);
    size_t bad = ok ? st_image_count_nonfinite(img) : 0;
    return ok && (!bad || st_fail(err, ST_ERR_RUNTIME, "%zu non-finite values in the result", bad));
}

PyObject *stpy_reference(PyObject *self, PyObject *args, PyObject *kw) {
    ref_req q = {0};
    st_image img = {0};
    st_err err = {0};
    bool ok = reference_args(&q, args, kw), done = false;
    if (ok) {
        PyThreadState *ts = PyEval_SaveThread();
        done = reference_c(&q, &img, &err);
        PyEval_RestoreThread(ts);
    }
    PyObject *out = NULL;
    if (ok && done) {
        PyObject *a = stpy_array(&img, 0), *s = a ? stpy_array(&img, 3) : NULL;
        out = a && s ? Py_BuildValue("(NN)", a, s) : (Py_XDECREF(a), Py_XDECREF(s), NULL);
    } else if (ok) {
        stpy_raise(&err);
    }
    st_image_free(&img);
    free(q.scene);
    stpy_strings_free(&q.sets);
    return out;
}

// {"r", "g", "b", "all"} of one metric (non-finite psnr stays inf).
static PyObject *rgba(const double v[4]) {
    return Py_BuildValue("{s:d,s:d,s:d,s:d}", "r", v[0], "g", v[1], "b", v[2], "all", v[3]);
}

// The metrics as `strahl compare --json` names them.
static PyObject *metrics_dict(const st_metrics *m, int w, int h) {
    PyObject *d =
        Py_BuildValue("{s:N,s:N,s:N,s:N,s:d,s:N,s:N,s:N,s:O,s:i,s:i}", "rmse", rgba(m->rmse),
                      "relmse", rgba(m->relmse), "psnr", rgba(m->psnr), "max_abs", rgba(m->max_abs),
                      "scale", m->scale, "scaled_rmse", rgba(m->scaled_rmse), "mean_a",
                      rgba(m->mean_a), "mean_b", rgba(m->mean_b), "reference_noise_warning",
                      st_metrics_noise_dominates(m) ? Py_True : Py_False, "width", w, "height", h);
    if (!d || !m->has_ref_noise) return d;
    const char *names[] = {"rmse_debiased", "relmse_debiased", "scaled_rmse_debiased",
                           "ref_noise_rms"};
    const double *vals[] = {m->rmse_debiased, m->relmse_debiased, m->scaled_rmse_debiased,
                            m->ref_noise_rms};
    for (int k = 0; k < 4; k++) {
        PyObject *v = rgba(vals[k]);
        if (!v || PyDict_SetItemString(d, names[k], v) < 0) Py_CLEAR(d);
        Py_XDECREF(v);
        if (!d) break;
    }
    return d;
}

PyObject *stpy_compare(PyObject *self, PyObject *args, PyObject *kw) {
    static char *kwlist[] = {"a", "b", "stderr", NULL};
    PyObject *ao, *bo, *so = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|O:compare", kwlist, &ao, &bo, &so)) return NULL;
    st_image a = {0}, b = {0}, se = {0};
    st_metrics m;
    st_err err = {0};
    // B's own standard-error channels unless stderr= gives them.
    bool ok = stpy_image(ao, "a", &a, NULL) &&
              stpy_image(bo, "b", &b, so == Py_None ? &se : NULL) &&
              (so == Py_None || stpy_image(so, "stderr", &se, NULL));
    PyObject *out = NULL;
    if (ok && !st_image_compare_noisy(&a, &b, &se, &m, &err)) {
        st_err_prefix(&err, "a vs b: ");
        stpy_raise(&err);
    } else if (ok) {
        out = metrics_dict(&m, a.width, a.height);
    }
    st_image_free(&a), st_image_free(&b), st_image_free(&se);
    return out;
}
