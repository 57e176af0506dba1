// The `strahl` module's table and initialisation.
#include "stpy.h"

int stpy_numpy_init(void);
int stpy_gl_init(void);
extern PyObject *stpy_error, *stpy_render_error;

#define KW(f) (PyCFunction)(void (*)(void))(f), METH_VARARGS | METH_KEYWORDS

static PyMethodDef methods[] = {
    {"render", KW(stpy_render),
     "render(scene, *, size=None, filter=None, set=None, enable=None, disable=None, "
     "frames=None) -> float32 (H, W, 3) linear radiance, the image `strahl render` writes "
     "for the same arguments"},
    {"reference", KW(stpy_reference),
     "reference(scene, *, size=None, spp=64, bounces=1, seed=0, aov='combined', filter=None, "
     "set=None, steps=256, estimator='area', visibility=True, threads=0) -> (image, stderr): "
     "the CPU reference of `strahl reference`"},
    {"compare", KW(stpy_compare),
     "compare(a, b, stderr=None) -> dict: the metrics of `strahl compare --json` of a against "
     "the reference b (arrays or EXR paths); debiased with b's standard error (stderr=, or "
     "the stderr channels of b's file)"},
    {"bench", KW(stpy_bench),
     "bench(scene, reference, sweep, *, set=None, size=None, filter=None, frames=10, warmup=2, "
     "metric='rmse', mode='recompute') -> list of dict: the rows `strahl bench` writes, keyed "
     "by the CSV's columns; sweep={\"module.param\": [v1, v2, ...]}, the first key is x"},
    {"modules", (PyCFunction)stpy_modules, METH_NOARGS,
     "modules() -> list of dict: every installed plugin's descriptor, as `strahl modules`"},
    {"read_exr", KW(stpy_read_exr),
     "read_exr(path) -> (image, stderr or None): an EXR's R, G, B and stderr.R/G/B"},
    {"write_exr", KW(stpy_write_exr),
     "write_exr(path, image, stderr=None): an (H, W, 3) image (and its standard error as "
     "stderr.R/G/B) as a 32-bit float EXR, written atomically"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "strahl",
    "strahl from Python: render, reference, compare and benchmark scenes with numpy arrays "
    "(docs/python.md)",
    -1, methods};

PyMODINIT_FUNC PyInit_strahl(void);
PyMODINIT_FUNC PyInit_strahl(void) {
    if (stpy_numpy_init() < 0 || stpy_gl_init() < 0) return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m) return NULL;
    stpy_error = PyErr_NewExceptionWithDoc(
        "strahl.Error", "Bad input: a file, key or value (the command line's exit code 2).",
        PyExc_ValueError, NULL);
    stpy_render_error = PyErr_NewExceptionWithDoc(
        "strahl.RenderError", "A runtime or GPU failure (the command line's exit code 1).",
        PyExc_RuntimeError, NULL);
    if (!stpy_error || !stpy_render_error || PyType_Ready(&stpy_world_type) < 0 ||
        PyModule_AddObjectRef(m, "Error", stpy_error) < 0 ||
        PyModule_AddObjectRef(m, "RenderError", stpy_render_error) < 0 ||
        PyModule_AddObjectRef(m, "World", (PyObject *)&stpy_world_type) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
