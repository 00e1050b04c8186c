/*
 * _io.c - the part of souptet's Python module that needs libsouptet-io
 * (OpenVDB, VTK): wrap() and writing .vtu. souptet/__init__.py imports it
 * only when one of those is called, so the rest works without it.
 *
 *   wrap(V, F, resolution) -> (V2, F2)
 *   write_vtu(mesh_capsule, path)
 */
#include "common.h"

#include "souptet/dist.h"
#include "souptet/pseudo.h"
#include "souptet/tetio.h"
#include "souptet/wrap.h"

#define CAPSULE_NAME "souptet.tetmesh"

static PyObject *py_wrap(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwlist[] = {"V", "F", "resolution", "fill_holes", "symmetry", NULL};
    PyObject *V, *F;
    Py_ssize_t cells = ST_DIST_DEFAULT_CELLS;
    int holes = st_pseudo_params_default().fill_holes, sym = st_pseudo_params_default().symmetry;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|n$pp:wrap", kwlist, &V, &F, &cells, &holes,
                                     &sym))
        return NULL;
    if (cells < 1 || cells > 65536)
        return py_fail("resolution must be in 1..65536, not %zd", cells);
    st_soup *soup = NULL;
    if (py_soup(V, F, &soup))
        return NULL;
    st_dist_params dp = st_dist_params_default();
    dp.cells = (size_t)cells;
    dp.max_bytes = py_max_bytes();
    st_pseudo_params pp = st_pseudo_params_default();
    pp.fill_holes = holes;
    pp.symmetry = sym;
    st_wrap_params wp = st_wrap_params_default();
    volatile int cancel = 0;
    st_progress prog = {NULL, NULL, &cancel};
    st_grid *g = NULL;
    st_soup *out = NULL;
    st_error e;
    st_error_clear(&e);
    st_status rc;
    PyObject *res = NULL;
    int sig = py_sig_begin(&cancel);
    Py_BEGIN_ALLOW_THREADS
    rc = st_pseudo_volume(&g, soup, &dp, &pp, NULL, &prog, &e);
    if (!rc)
        rc = st_wrap_field(&out, g, &wp, NULL, &prog, &e);
    if (!rc && cancel)
        rc = st_error_set(&e, ST_ECANCELLED, NULL, 0, "cancelled");
    Py_END_ALLOW_THREADS
    if (!py_sig_end(sig)) {
        if (rc) {
            py_raise(&e, NULL);
        } else {
            npy_intp dv[2] = {(npy_intp)out->nverts, 3}, df[2] = {(npy_intp)out->ntris, 3};
            PyArrayObject *V2 = (PyArrayObject *)PyArray_SimpleNew(2, dv, NPY_FLOAT64);
            PyArrayObject *F2 = (PyArrayObject *)PyArray_SimpleNew(2, df, NPY_INT64);
            if (V2 && F2) {
                memcpy(PyArray_DATA(V2), out->xyz, 3 * out->nverts * sizeof(double));
                int64_t *f = PyArray_DATA(F2);
                for (size_t i = 0; i < 3 * out->ntris; i++)
                    f[i] = out->tris[i];
                res = Py_BuildValue("(NN)", V2, F2);
            } else {
                Py_XDECREF(V2);
                Py_XDECREF(F2);
            }
        }
    }
    st_soup_free(out);
    st_grid_free(g);
    st_soup_free(soup);
    return res;
}

static PyObject *py_write_vtu(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *cap, *path = NULL;
    if (!PyArg_ParseTuple(args, "OO&:write_vtu", &cap, PyUnicode_FSConverter, &path))
        return NULL;
    const st_tetmesh *m = PyCapsule_GetPointer(cap, CAPSULE_NAME);
    if (!m) {
        Py_DECREF(path);
        return NULL;
    }
    const char *p = PyBytes_AS_STRING(path);
    st_error e;
    st_error_clear(&e);
    st_status rc;
    Py_BEGIN_ALLOW_THREADS
    rc = st_tetmesh_save(m, p, NULL, &e);
    Py_END_ALLOW_THREADS
    PyObject *res = rc ? py_raise(&e, p) : (Py_INCREF(Py_None), Py_None);
    Py_DECREF(path);
    return res;
}

static PyMethodDef methods[] = {
    {"wrap", (PyCFunction)(void (*)(void))py_wrap, METH_VARARGS | METH_KEYWORDS,
     "wrap(V, F, resolution) -> (V2, F2)"},
    {"write_vtu", py_write_vtu, METH_VARARGS, "write_vtu(mesh_capsule, path)"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef moddef = {PyModuleDef_HEAD_INIT, "souptet._io",
                                    "souptet's OpenVDB and VTK part (libsouptet-io).", -1,
                                    methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__io(void)
{
    import_array();
    PyObject *core = PyImport_ImportModule("souptet._core");
    if (!core)
        return NULL;
    py_error = PyObject_GetAttrString(core, "Error");
    Py_DECREF(core);
    if (!py_error)
        return NULL;
    return PyModule_Create(&moddef);
}
