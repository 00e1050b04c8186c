/*
 * _core.c - souptet's Python module over libsouptet (the C core: no VTK,
 * no OpenVDB). The public API is souptet/__init__.py's; this module
 * gives it plain values (arrays, dicts, a capsule holding the mesh).
 *
 *   read(path) -> (V, F)
 *   read_parts(path, mode) -> (V, F, part, names)   (parts.h)
 *   mesh(V, F, cells, size, tets, tries, seed, offset, threads, progress)
 *       -> dict (points, tets, boundary, embed_tet, embed_bary, ...,
 *          "_mesh": capsule "souptet.tetmesh")
 *   pseudo_volume(V, F, resolution) / distance(V, F, resolution, band)
 *       -> dict (values, origin, voxel, dims)
 *   write(capsule, path, msh_version, binary)   .msh .node/.ele .mesh
 *
 * The GIL is released while the library works; Ctrl-C cancels through
 * the library's cancel flag (common.h).
 */
#include "common.h"

#include "souptet/dist.h"
#include "souptet/embed.h"
#include "souptet/grid.h"
#include "souptet/meta.h"
#include "souptet/outfile.h"
#include "souptet/parts.h"
#include "souptet/pipeline.h"
#include "souptet/pseudo.h"
#include "souptet/tetformat.h"
#include "souptet/tetmesh.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#define CAPSULE_NAME "souptet.tetmesh"

/* ---- read ------------------------------------------------------------- */

static PyObject *soup_arrays(const st_soup *s)
{
    npy_intp dv[2] = {(npy_intp)s->nverts, 3}, df[2] = {(npy_intp)s->ntris, 3};
    PyArrayObject *V = (PyArrayObject *)PyArray_SimpleNew(2, dv, NPY_FLOAT64);
    PyArrayObject *F = (PyArrayObject *)PyArray_SimpleNew(2, df, NPY_INT64);
    if (!V || !F) {
        Py_XDECREF(V);
        Py_XDECREF(F);
        return NULL;
    }
    memcpy(PyArray_DATA(V), s->xyz, 3 * s->nverts * sizeof(double));
    int64_t *f = PyArray_DATA(F);
    for (size_t i = 0; i < 3 * s->ntris; i++)
        f[i] = s->tris[i];
    return Py_BuildValue("(NN)", V, F);
}

static PyObject *py_read(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *path = NULL;
    if (!PyArg_ParseTuple(args, "O&:read", PyUnicode_FSConverter, &path))
        return NULL;
    const char *p = PyBytes_AS_STRING(path);
    st_soup *s = NULL;
    st_soup_warnings w;
    st_error e;
    st_error_clear(&e);
    st_status rc;
    Py_BEGIN_ALLOW_THREADS
    rc = st_soup_read_warn(&s, p, &w, &e);
    Py_END_ALLOW_THREADS
    PyObject *res = NULL;
    if (rc) {
        py_raise(&e, p);
    } else {
        res = soup_arrays(s);
        if (res && w.count) {
            char buf[1200];
            st_error_format(&w.first, buf, sizeof buf);
            if (PyErr_WarnFormat(PyExc_UserWarning, 1, "%s (%zu note%s from the reader)",
                                 buf, w.count, w.count == 1 ? "" : "s") < 0)
                Py_CLEAR(res);
        }
    }
    st_soup_free(s);
    Py_DECREF(path);
    return res;
}

/* The parts of a file (parts.h, soupmesh --parts MODE): (V, F, part, names),
 * part int32 (len(F),), names a list of str. */
static PyObject *py_read_parts(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *path = NULL;
    const char *mode = "auto";
    if (!PyArg_ParseTuple(args, "O&|s:read_parts", PyUnicode_FSConverter, &path, &mode))
        return NULL;
    const int md = st_parts_mode_from_name(mode);
    if (md <= ST_PARTS_NONE) {
        Py_DECREF(path);
        return py_fail("mode must be auto, names or pieces, not '%s'", mode);
    }
    const char *p = PyBytes_AS_STRING(path);
    st_soup *s = NULL;
    st_parts parts;
    memset(&parts, 0, sizeof parts);
    st_error e;
    st_error_clear(&e);
    st_status rc;
    Py_BEGIN_ALLOW_THREADS
    rc = st_soup_read(&s, p, &e);
    if (!rc)
        rc = st_parts_split(&parts, s, (st_parts_mode)md, &e);
    Py_END_ALLOW_THREADS
    PyObject *res = NULL, *vf = NULL, *names = NULL;
    PyArrayObject *P = NULL;
    if (rc) {
        py_raise(&e, p);
        goto done;
    }
    npy_intp dn[1] = {(npy_intp)s->ntris};
    P = (PyArrayObject *)PyArray_SimpleNew(1, dn, NPY_INT32);
    vf = soup_arrays(s);
    names = PyList_New((Py_ssize_t)parts.nparts);
    if (!P || !vf || !names)
        goto done;
    int32_t *pp = PyArray_DATA(P);
    for (size_t t = 0; t < s->ntris; t++)
        pp[t] = parts.tri_part[t];
    for (size_t k = 0; k < parts.nparts; k++) {
        PyObject *n = PyUnicode_FromString(parts.names[k]);
        if (!n)
            goto done;
        PyList_SET_ITEM(names, (Py_ssize_t)k, n);
    }
    res = Py_BuildValue("(OOOO)", PyTuple_GET_ITEM(vf, 0), PyTuple_GET_ITEM(vf, 1), P, names);
done:
    Py_XDECREF(P);
    Py_XDECREF(vf);
    Py_XDECREF(names);
    st_parts_free(&parts);
    st_soup_free(s);
    Py_DECREF(path);
    return res;
}

/* mesh()'s parts: None, a mode ("auto", "names", "pieces": st_parts_split
 * of the arrays, which name nothing), or a (len(F),) integer array of part
 * indices with part_names (None or a list of str). 0: *out filled (or
 * zeroed for None); -1: an exception is set. */
static int py_parts(PyObject *parts_o, PyObject *names_o, const st_soup *soup, st_parts *out)
{
    memset(out, 0, sizeof *out);
    if (parts_o == Py_None)
        return 0;
    st_error e;
    st_error_clear(&e);
    if (PyUnicode_Check(parts_o)) {
        const char *mode = PyUnicode_AsUTF8(parts_o);
        const int md = mode ? st_parts_mode_from_name(mode) : -1;
        if (md <= ST_PARTS_NONE) {
            PyErr_Clear();
            py_fail("parts must be an array, \"auto\", \"names\" or \"pieces\"");
            return -1;
        }
        if (st_parts_split(out, soup, (st_parts_mode)md, &e)) {
            py_raise(&e, NULL);
            return -1;
        }
        return 0;
    }
    PyArrayObject *a = (PyArrayObject *)PyArray_FROMANY(parts_o, NPY_INT64, 1, 1, NPY_ARRAY_CARRAY_RO);
    if (!a)
        return -1;
    const npy_intp n = PyArray_DIM(a, 0);
    uint32_t *idx = NULL;
    const char **names = NULL;
    PyObject *seq = NULL;
    Py_ssize_t nn = 0;
    int rc = -1;
    if ((size_t)n != soup->ntris) {
        py_fail("parts must have one entry per row of F (%zu), not %zd", soup->ntris, (Py_ssize_t)n);
        goto out;
    }
    idx = malloc((size_t)(n ? n : 1) * sizeof *idx);
    if (!idx) {
        PyErr_NoMemory();
        goto out;
    }
    const int64_t *v = PyArray_DATA(a);
    for (npy_intp t = 0; t < n; t++) {
        if (v[t] < 0 || v[t] >= ST_PARTS_MAX) {
            py_fail("parts[%zd] is %lld, not a part index in 0..%d", (Py_ssize_t)t,
                    (long long)v[t], ST_PARTS_MAX - 1);
            goto out;
        }
        idx[t] = (uint32_t)v[t];
    }
    if (names_o != Py_None) {
        seq = PySequence_Fast(names_o, "part_names must be a list of str or None");
        if (!seq)
            goto out;
        nn = PySequence_Fast_GET_SIZE(seq);
        names = calloc((size_t)(nn ? nn : 1), sizeof *names);
        if (!names) {
            PyErr_NoMemory();
            goto out;
        }
        for (Py_ssize_t k = 0; k < nn; k++) {
            PyObject *it = PySequence_Fast_GET_ITEM(seq, k);
            if (!PyUnicode_Check(it) || !(names[k] = PyUnicode_AsUTF8(it))) {
                PyErr_Clear();
                PyErr_SetString(PyExc_TypeError, "part_names must hold str (UTF-8)");
                goto out;
            }
        }
    }
    if (st_parts_from_indices(out, idx, (size_t)n, names, (size_t)nn, &e)) {
        py_raise(&e, NULL);
        goto out;
    }
    rc = 0;
out:
    free(idx);
    free(names);
    Py_XDECREF(seq);
    Py_DECREF(a);
    return rc;
}

/* ---- souptet.Cancel: the library's cancel flag, as an object -------------- */

/* A flag another thread (a UI's event loop) sets while mesh() runs with
 * the GIL released: the library polls it itself (progress.h), so the run
 * stops within about 0.1 s of work, not at the next progress report. */
typedef struct {
    PyObject_HEAD
    volatile int flag;
} CancelObject;

static PyObject *py_cancelled;   /* souptet.Cancelled */

static PyObject *cancel_set(PyObject *self, PyObject *noargs)
{
    (void)noargs;
    st_progress_cancel(&((CancelObject *)self)->flag);
    Py_RETURN_NONE;
}

static PyObject *cancel_clear(PyObject *self, PyObject *noargs)
{
    (void)noargs;
    __atomic_store_n(&((CancelObject *)self)->flag, 0, __ATOMIC_RELAXED);
    Py_RETURN_NONE;
}

static PyObject *cancel_is_set(PyObject *self, PyObject *noargs)
{
    (void)noargs;
    return PyBool_FromLong(__atomic_load_n(&((CancelObject *)self)->flag, __ATOMIC_RELAXED));
}

static PyMethodDef cancel_methods[] = {
    {"set", cancel_set, METH_NOARGS, "set(): ask the run given this object to stop."},
    {"clear", cancel_clear, METH_NOARGS, "clear(): make the object usable for another run."},
    {"is_set", cancel_is_set, METH_NOARGS, "is_set() -> bool"},
    {NULL, NULL, 0, NULL}};

static PyTypeObject CancelType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "souptet.Cancel",
    .tp_basicsize = sizeof(CancelObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Cancel(): a flag to stop souptet.mesh(..., cancel=c) from another thread.\n"
              "c.set() makes the run stop within about 0.1 s of work and raise\n"
              "souptet.Cancelled; c.clear() resets it; c.is_set() says.",
    .tp_methods = cancel_methods,
    .tp_new = PyType_GenericNew,
};

/* ---- progress ------------------------------------------------------------ */

/* What the library's callbacks share; every field is touched with the GIL
 * held. */
typedef struct py_prog {
    PyObject *fn;             /* the progress callable, or NULL */
    volatile int cancel;      /* the library's cancel flag, unless ... */
    volatile int *flag;       /* ... a souptet.Cancel's: the one in use */
    int failed;               /* the callable raised: exc_* hold it */
    PyObject *exc_type, *exc_value, *exc_tb;
    const char *stage;        /* the latest st_progress report */
    double fraction;
    const char *sent_stage;   /* the latest one passed on */
    double sent_fraction;
} py_prog;

static int set_item(PyObject *d, const char *key, PyObject *v)
{
    if (!v)
        return -1;
    int rc = PyDict_SetItemString(d, key, v);
    Py_DECREF(v);
    return rc;
}

/* Call the callable with an event dict (GIL held); on an exception keep
 * it and cancel the run. */
static void prog_send(py_prog *pp, PyObject *d)
{
    if (!d || set_item(d, "stage", pp->stage ? PyUnicode_FromString(pp->stage)
                                             : (Py_INCREF(Py_None), Py_None)) ||
        set_item(d, "fraction", PyFloat_FromDouble(pp->fraction))) {
        Py_XDECREF(d);
        goto fail;
    }
    PyObject *r = PyObject_CallOneArg(pp->fn, d);
    Py_DECREF(d);
    if (r) {
        Py_DECREF(r);
        return;
    }
fail:
    pp->failed = 1;
    PyErr_Fetch(&pp->exc_type, &pp->exc_value, &pp->exc_tb);
    st_progress_cancel(pp->flag);
}

static void on_progress(void *ctx, const char *stage, double fraction)
{
    py_prog *pp = ctx;
    PyGILState_STATE g = PyGILState_Ensure();
    pp->stage = stage;
    pp->fraction = fraction;
    /* at most every 1% of a stage, so the callable does not slow the run */
    if (pp->fn && !pp->failed &&
        (stage != pp->sent_stage || fraction >= pp->sent_fraction + 0.01 || fraction >= 1.0 ||
         fraction < pp->sent_fraction)) {
        pp->sent_stage = stage;
        pp->sent_fraction = fraction;
        PyObject *d = PyDict_New();
        if (d && set_item(d, "what", PyUnicode_FromString("progress"))) {
            Py_CLEAR(d);
        }
        prog_send(pp, d);
    }
    PyGILState_Release(g);
}

static void on_event(void *ctx, const st_pipeline_event *ev)
{
    py_prog *pp = ctx;
    PyGILState_STATE g = PyGILState_Ensure();
    if (pp->fn && !pp->failed) {
        PyObject *d = PyDict_New();
        int bad = !d || set_item(d, "what", PyUnicode_FromString(ev->what)) ||
                  set_item(d, "k", PyLong_FromSize_t(ev->k)) ||
                  set_item(d, "h", PyFloat_FromDouble(ev->h)) ||
                  set_item(d, "tets", PyLong_FromSize_t(ev->tets)) ||
                  set_item(d, "seconds", PyFloat_FromDouble(ev->seconds)) ||
                  set_item(d, "voxel", PyFloat_FromDouble(ev->voxel)) ||
                  set_item(d, "field_dims", Py_BuildValue("(nnn)", (Py_ssize_t)ev->field_dims[0],
                                                          (Py_ssize_t)ev->field_dims[1],
                                                          (Py_ssize_t)ev->field_dims[2]));
        if (!bad && ev->fit)
            bad = set_item(d, "phase", PyUnicode_FromString(ev->fit->phase)) ||
                  set_item(d, "iteration", PyLong_FromLong(ev->fit->iter)) ||
                  set_item(d, "min_dihedral", PyFloat_FromDouble(ev->fit->min_dihedral)) ||
                  set_item(d, "max_dihedral", PyFloat_FromDouble(ev->fit->max_dihedral)) ||
                  set_item(d, "max_distance", PyFloat_FromDouble(ev->fit->max_distance));
        if (!bad && ev->candidate)
            bad = set_item(d, "failed", PyBool_FromLong(ev->candidate->failed));
        if (bad)
            Py_CLEAR(d);
        prog_send(pp, d);
    }
    PyGILState_Release(g);
}

/* After the call: the callable's exception, if it raised (returns -1). */
static int prog_finish(py_prog *pp)
{
    if (!pp->failed)
        return 0;
    PyErr_Restore(pp->exc_type, pp->exc_value, pp->exc_tb);
    pp->exc_type = pp->exc_value = pp->exc_tb = NULL;
    return -1;
}

/* ---- mesh --------------------------------------------------------------- */

static void capsule_free(PyObject *cap)
{
    st_tetmesh_free(PyCapsule_GetPointer(cap, CAPSULE_NAME));
}

/* The result's parts, part_share and part_names (None without parts). */
static int set_parts(PyObject *d, const st_tetmesh *m)
{
    const st_tet_array *pa = st_tetmesh_find_array(m, "part", ST_ON_CELLS);
    const st_tet_array *sa = st_tetmesh_find_array(m, "part_share", ST_ON_CELLS);
    if (!pa || !sa)
        return set_item(d, "parts", (Py_INCREF(Py_None), Py_None)) ||
               set_item(d, "part_share", (Py_INCREF(Py_None), Py_None)) ||
               set_item(d, "part_names", (Py_INCREF(Py_None), Py_None));
    npy_intp dn[1] = {(npy_intp)m->ntets};
    PyArrayObject *P = (PyArrayObject *)PyArray_SimpleNew(1, dn, NPY_INT32);
    PyArrayObject *S = (PyArrayObject *)PyArray_SimpleNew(1, dn, NPY_FLOAT64);
    const char **nm = NULL;
    size_t n = 0;
    st_error e;
    st_error_clear(&e);
    if (!P || !S || st_parts_of_mesh(&nm, &n, m, &e)) {
        Py_XDECREF(P);
        Py_XDECREF(S);
        if (!PyErr_Occurred())
            PyErr_NoMemory();
        return -1;
    }
    int32_t *p = PyArray_DATA(P);
    for (size_t t = 0; t < m->ntets; t++)
        p[t] = (int32_t)pa->values[t];
    memcpy(PyArray_DATA(S), sa->values, m->ntets * sizeof(double));
    PyObject *L = PyList_New((Py_ssize_t)n);
    for (size_t k = 0; L && k < n; k++) {
        const char *c = nm[k] ? nm[k] : "";
        PyObject *s = PyUnicode_DecodeUTF8(c, (Py_ssize_t)strlen(c), "replace");
        if (!s) {
            Py_CLEAR(L);
            break;
        }
        PyList_SET_ITEM(L, (Py_ssize_t)k, s);
    }
    free((void *)nm);
    if (!L) {
        Py_DECREF(P);
        Py_DECREF(S);
        return -1;
    }
    return set_item(d, "parts", (PyObject *)P) || set_item(d, "part_share", (PyObject *)S) ||
           set_item(d, "part_names", L);
}

static PyObject *mesh_result(st_tetmesh *m, const st_pipeline_stats *st, const int64_t *et,
                             const double *eb, size_t nv)
{
    st_error e;
    st_error_clear(&e);
    uint32_t *faces = NULL;
    size_t nfaces = 0;
    if (st_tetmesh_boundary(m, &faces, NULL, &nfaces, &e))
        return py_raise(&e, NULL);
    npy_intp dp[2] = {(npy_intp)m->npoints, 3}, dt[2] = {(npy_intp)m->ntets, 4},
             db[2] = {(npy_intp)nfaces, 3}, de[1] = {(npy_intp)nv}, dbary[2] = {(npy_intp)nv, 4};
    PyArrayObject *P = (PyArrayObject *)PyArray_SimpleNew(2, dp, NPY_FLOAT64);
    PyArrayObject *T = (PyArrayObject *)PyArray_SimpleNew(2, dt, NPY_INT64);
    PyArrayObject *B = (PyArrayObject *)PyArray_SimpleNew(2, db, NPY_INT64);
    PyArrayObject *ET = (PyArrayObject *)PyArray_SimpleNew(1, de, NPY_INT64);
    PyArrayObject *EB = (PyArrayObject *)PyArray_SimpleNew(2, dbary, NPY_FLOAT64);
    PyObject *d = PyDict_New();
    PyObject *res = NULL;
    if (!P || !T || !B || !ET || !EB || !d)
        goto done;
    memcpy(PyArray_DATA(P), m->xyz, 3 * m->npoints * sizeof(double));
    int64_t *t = PyArray_DATA(T);
    for (size_t i = 0; i < 4 * m->ntets; i++)
        t[i] = m->tets[i];
    int64_t *b = PyArray_DATA(B);
    for (size_t i = 0; i < 3 * nfaces; i++)
        b[i] = faces[i];
    memcpy(PyArray_DATA(ET), et, nv * sizeof(int64_t));
    memcpy(PyArray_DATA(EB), eb, 4 * nv * sizeof(double));
    const st_pipeline_candidate *c = &st->candidates[st->best];
    if (set_item(d, "points", (Py_INCREF(P), (PyObject *)P)) ||
        set_item(d, "tets", (Py_INCREF(T), (PyObject *)T)) ||
        set_item(d, "boundary", (Py_INCREF(B), (PyObject *)B)) ||
        set_item(d, "embed_tet", (Py_INCREF(ET), (PyObject *)ET)) ||
        set_item(d, "embed_bary", (Py_INCREF(EB), (PyObject *)EB)) ||
        set_item(d, "min_dihedral", PyFloat_FromDouble(c->min_dihedral)) ||
        set_item(d, "max_dihedral", PyFloat_FromDouble(c->max_dihedral)) ||
        set_item(d, "encloses", PyBool_FromLong(st->encloses)) ||
        set_item(d, "converged", PyBool_FromLong(c->converged)) ||
        set_item(d, "h", PyFloat_FromDouble(st->h)) ||
        set_item(d, "seed", PyLong_FromUnsignedLongLong(c->seed)) ||
        set_item(d, "candidates", PyLong_FromSize_t(st->ncandidates)) ||
        set_item(d, "max_distance", PyFloat_FromDouble(c->max_distance)) ||
        set_item(d, "guessed", PyFloat_FromDouble(
                     st->guess.boundary_faces
                         ? (double)st->guess.fill_faces / (double)st->guess.boundary_faces
                         : 0.0)) ||
        set_item(d, "seconds", PyFloat_FromDouble(st->seconds_total)) ||
        set_parts(d, m))
        goto done;
    PyObject *cap = PyCapsule_New(m, CAPSULE_NAME, capsule_free);
    if (!cap)
        goto done;
    if (set_item(d, "_mesh", cap))   /* the capsule owns m from here */
        goto done;
    res = d;
    d = NULL;
done:
    free(faces);
    Py_XDECREF(P);
    Py_XDECREF(T);
    Py_XDECREF(B);
    Py_XDECREF(ET);
    Py_XDECREF(EB);
    Py_XDECREF(d);
    return res;
}

static int opt_double(PyObject *o, const char *name, double *out)
{
    if (o == Py_None)
        return 0;
    if (PyBool_Check(o) || !PyNumber_Check(o)) {
        py_fail("%s must be a number or None", name);
        return -1;
    }
    *out = PyFloat_AsDouble(o);
    return *out == -1.0 && PyErr_Occurred() ? -1 : 0;
}

static int opt_size(PyObject *o, const char *name, size_t lo, size_t hi, size_t *out)
{
    if (o == Py_None)
        return 0;
    if (PyBool_Check(o) || !PyLong_Check(o)) {
        py_fail("%s must be an integer", name);
        return -1;
    }
    int overflow = 0;
    long long v = PyLong_AsLongLongAndOverflow(o, &overflow);
    if (v == -1 && PyErr_Occurred())
        return -1;
    if (overflow || v < (long long)lo || (unsigned long long)v > hi) {
        py_fail("%s must be in %zu..%zu", name, lo, hi);
        return -1;
    }
    *out = (size_t)v;
    return 0;
}

/* A bool keyword into *out (NULL: the default, left as it is). */
static int opt_flag(PyObject *o, int *out)
{
    if (!o)
        return 0;
    const int v = PyObject_IsTrue(o);
    if (v < 0)
        return -1;
    *out = v;
    return 0;
}

static PyObject *py_mesh(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwlist[] = {"V", "F", "cells", "size", "tets", "tries", "seed",
                             "offset", "threads", "progress", "float32", "cancel", "try_all",
                             "parts", "part_names", "fill_holes", "symmetry", NULL};
    PyObject *V, *F, *cells_o = NULL, *size_o = Py_None, *tets_o = Py_None, *tries_o = NULL,
                     *seed_o = NULL, *offset_o = NULL, *threads_o = NULL, *progress = Py_None,
                     *f32_o = Py_False, *cancel_o = Py_None, *try_all_o = Py_False,
                     *parts_o = Py_None, *pnames_o = Py_None, *holes_o = NULL, *sym_o = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|$OOOOOOOOOOOOOOO:mesh", kwlist, &V, &F,
                                     &cells_o, &size_o, &tets_o, &tries_o, &seed_o, &offset_o,
                                     &threads_o, &progress, &f32_o, &cancel_o, &try_all_o,
                                     &parts_o, &pnames_o, &holes_o, &sym_o))
        return NULL;
    if (cancel_o != Py_None && !PyObject_TypeCheck(cancel_o, &CancelType)) {
        PyErr_SetString(PyExc_TypeError, "cancel must be a souptet.Cancel or None");
        return NULL;
    }
    st_pipeline_params p = st_pipeline_params_default();
    if (opt_flag(holes_o, &p.fill_holes) || opt_flag(sym_o, &p.symmetry))
        return NULL;
    size_t threads = 0, seed = (size_t)p.seed;
    if (cells_o && opt_size(cells_o, "cells", 1, ST_PIPELINE_MAX_CELLS, &p.cells))
        return NULL;
    if (opt_double(size_o, "size", &p.h))
        return NULL;
    if (size_o != Py_None && !(p.h >= 1e-300 && p.h <= 1e300))
        return py_fail("size must be a positive cell width in model units, not %g", p.h);
    if (opt_size(tets_o, "tets", 10, 100000000, &p.target_tets))
        return NULL;
    if (tries_o && opt_size(tries_o, "tries", 1, ST_PIPELINE_MAX_TRIES, &p.tries))
        return NULL;
    if (seed_o && opt_size(seed_o, "seed", 0, SIZE_MAX, &seed))
        return NULL;
    p.seed = seed;
    int try_all = PyObject_IsTrue(try_all_o);
    if (try_all < 0)
        return NULL;
    p.try_all = try_all;
    if (offset_o && opt_double(offset_o, "offset", &p.offset_ratio))
        return NULL;
    if (!(p.offset_ratio >= 1e-3 && p.offset_ratio <= 10.0))
        return py_fail("offset must be in 0.001..10 (cell widths), not %g", p.offset_ratio);
    if (threads_o && opt_size(threads_o, "threads", 0, 4096, &threads))
        return NULL;
    if (progress != Py_None && !PyCallable_Check(progress)) {
        PyErr_SetString(PyExc_TypeError, "progress must be callable or None");
        return NULL;
    }
    int f32 = PyObject_IsTrue(f32_o);
    if (f32 < 0)
        return NULL;
    p.float32 = f32;
    st_soup *soup = NULL;
    if (py_soup(V, F, &soup))
        return NULL;
    st_parts parts;
    if (py_parts(parts_o, pnames_o, soup, &parts)) {
        st_soup_free(soup);
        return NULL;
    }
    if (parts.nparts)
        p.parts = &parts;

    st_error e;
    st_error_clear(&e);
    p.max_bytes = py_max_bytes();
    py_prog pp;
    memset(&pp, 0, sizeof pp);
    pp.fn = progress != Py_None ? progress : NULL;
    pp.sent_fraction = -1.0;
    pp.flag = cancel_o != Py_None ? &((CancelObject *)cancel_o)->flag : &pp.cancel;
    p.on_event = on_event;
    p.on_event_ctx = &pp;
    st_progress prog = {on_progress, &pp, pp.flag};
    st_pipeline_stats st;
    memset(&st, 0, sizeof st);
    st_tetmesh *m = NULL;
    int64_t *et = NULL;
    double *eb = NULL;
    PyObject *res = NULL;
    size_t nout = 0;

    /* soupmesh refuses lattices over its memory limit before laying any */
    double h = st_pipeline_cell_width(soup, &p), ltets, at_once;
    double need = st_pipeline_lattice_bytes(soup, h, p.tries, &ltets, &at_once);
    if (p.max_bytes && need > (double)p.max_bytes) {
        py_fail("cell width %g lays lattices of up to %.0f tets (%.0f at a time), about "
                "%.1f MiB, over 80%% of this machine's memory (%.1f MiB): use fewer cells or "
                "tries, or a larger size", h, ltets, at_once, need / 1048576.0,
                (double)p.max_bytes / 1048576.0);
        goto done;
    }
    et = malloc(soup->nverts * sizeof *et);
    eb = malloc(soup->nverts * 4 * sizeof *eb);
    if (!et || !eb) {
        PyErr_NoMemory();
        goto done;
    }
    int sig = py_sig_begin(pp.flag);
    st_status rc;
    Py_BEGIN_ALLOW_THREADS
    int old_threads = omp_get_max_threads();
    if (threads)
        omp_set_num_threads((int)threads);
    rc = st_pipeline_run(&m, &st, soup, &p, &prog, &e);
    if (!rc && !*pp.flag)
        rc = st_embed_compute(et, eb, &nout, NULL, m, soup, &e);
    else if (!rc)
        rc = st_error_set(&e, ST_ECANCELLED, NULL, 0, "cancelled");
    omp_set_num_threads(old_threads);
    Py_END_ALLOW_THREADS
    if (py_sig_end(sig) || prog_finish(&pp))
        goto done;
    if (rc == ST_ECANCELLED && cancel_o != Py_None) {
        PyErr_SetString(py_cancelled, "souptet.mesh: cancelled (its souptet.Cancel was set)");
        goto done;
    }
    if (rc) {
        py_raise(&e, NULL);
        goto done;
    }
    char hist[256];
    if (p.h > 0)
        snprintf(hist, sizeof hist, "python3: souptet.mesh(size=%.17g", p.h);
    else
        snprintf(hist, sizeof hist, "python3: souptet.mesh(cells=%zu", p.cells);
    if (p.target_tets)
        snprintf(hist + strlen(hist), sizeof hist - strlen(hist), ", tets=%zu", p.target_tets);
    snprintf(hist + strlen(hist), sizeof hist - strlen(hist),
             ", tries=%zu, seed=%llu, offset=%.15g)", p.tries, (unsigned long long)p.seed,
             p.offset_ratio);
    if (st_meta_history_append(&m->meta, hist)) {
        PyErr_NoMemory();
        goto done;
    }
    res = mesh_result(m, &st, et, eb, soup->nverts);
    if (res)
        m = NULL;   /* the capsule has it */
done:
    Py_XDECREF(pp.exc_type);
    Py_XDECREF(pp.exc_value);
    Py_XDECREF(pp.exc_tb);
    free(et);
    free(eb);
    free(st.candidates);
    st_parts_tag_stats_free(&st.parts);
    st_parts_free(&parts);
    st_tetmesh_free(m);
    st_soup_free(soup);
    return res;
}

/* ---- fields --------------------------------------------------------------- */

/* A grid's values as a float32 (nx, ny, nz) array indexed [i, j, k] (Fortran
 * order over the library's x-fastest storage), with origin, voxel, dims. */
static PyObject *grid_result(const st_grid *g)
{
    npy_intp dims[3] = {(npy_intp)g->nx, (npy_intp)g->ny, (npy_intp)g->nz};
    PyArrayObject *a = (PyArrayObject *)PyArray_New(&PyArray_Type, 3, dims, NPY_FLOAT32, NULL,
                                                    NULL, 0, NPY_ARRAY_F_CONTIGUOUS, NULL);
    if (!a)
        return NULL;
    memcpy(PyArray_DATA(a), g->data, st_grid_count(g) * sizeof(float));
    return Py_BuildValue("{s:N,s:(ddd),s:d,s:d}", "values", a, "origin", g->origin[0],
                         g->origin[1], g->origin[2], "voxel", g->voxel, "band", g->band);
}

static PyObject *field_call(PyObject *args, PyObject *kw, int signs)
{
    static char *kwlist_d[] = {"V", "F", "resolution", "band", NULL};
    static char *kwlist_s[] = {"V", "F", "resolution", "fill_holes", "symmetry", NULL};
    PyObject *V, *F, *res_o = NULL, *band_o = NULL, *holes_o = NULL, *sym_o = NULL;
    if (signs ? !PyArg_ParseTupleAndKeywords(args, kw, "OO|O$OO:pseudo_volume", kwlist_s, &V,
                                             &F, &res_o, &holes_o, &sym_o)
              : !PyArg_ParseTupleAndKeywords(args, kw, "OO|OO:distance", kwlist_d, &V, &F,
                                             &res_o, &band_o))
        return NULL;
    st_pseudo_params pp = st_pseudo_params_default();
    if (opt_flag(holes_o, &pp.fill_holes) || opt_flag(sym_o, &pp.symmetry))
        return NULL;
    st_dist_params dp = st_dist_params_default();
    dp.cells = ST_DIST_DEFAULT_CELLS;
    if (res_o && opt_size(res_o, "resolution", 1, 65536, &dp.cells))
        return NULL;
    if (band_o && opt_double(band_o, "band", &dp.band))
        return NULL;
    if (!(dp.band >= ST_DIST_MIN_BAND))
        return py_fail("band must be at least %g voxels (or math.inf), not %g",
                       ST_DIST_MIN_BAND, dp.band);
    if (isfinite(dp.band) && dp.band > 1e6)
        return py_fail("band must be at most 1e6 voxels (or math.inf)");
    dp.max_bytes = py_max_bytes();
    st_soup *soup = NULL;
    if (py_soup(V, F, &soup))
        return NULL;
    volatile int cancel = 0;
    st_progress prog = {NULL, NULL, &cancel};
    st_grid *g = NULL;
    st_error e;
    st_error_clear(&e);
    st_status rc;
    PyObject *res = NULL;
    int sig = py_sig_begin(&cancel);
    Py_BEGIN_ALLOW_THREADS
    rc = signs ? st_pseudo_volume(&g, soup, &dp, &pp, NULL, &prog, &e)
               : st_dist_field(&g, soup, &dp, &prog, &e);
    if (!rc && cancel)
        rc = st_error_set(&e, ST_ECANCELLED, NULL, 0, "cancelled");
    Py_END_ALLOW_THREADS
    if (!py_sig_end(sig)) {
        if (rc)
            py_raise(&e, NULL);
        else
            res = grid_result(g);
    }
    st_grid_free(g);
    st_soup_free(soup);
    return res;
}

static PyObject *py_distance(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    return field_call(args, kw, 0);
}

static PyObject *py_pseudo_volume(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    return field_call(args, kw, 1);
}

/* ---- write ---------------------------------------------------------------- */

static PyObject *py_write(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *cap, *path = NULL;
    int version = 41, binary = 0;
    if (!PyArg_ParseTuple(args, "OO&|ip:write", &cap, PyUnicode_FSConverter, &path, &version,
                          &binary))
        return NULL;
    const st_tetmesh *m = PyCapsule_GetPointer(cap, CAPSULE_NAME);
    if (!m) {
        Py_DECREF(path);
        return NULL;
    }
    const char *p = PyBytes_AS_STRING(path);
    st_error e;
    st_error_clear(&e);
    st_status rc = ST_OK;
    st_tetformat f = st_tetformat_from_path(p);
    if (version != 41 && version != 22 && version != 4 && version != 2) {
        Py_DECREF(path);
        return py_fail("msh_version must be 41 or 22, not %d", version);
    }
    if (f != ST_TETFORMAT_MSH && f != ST_TETFORMAT_TETGEN && f != ST_TETFORMAT_MEDIT) {
        Py_DECREF(path);
        return py_fail("'%s': not a .msh, .node, .ele or .mesh path", p);
    }
    Py_BEGIN_ALLOW_THREADS
    if (f == ST_TETFORMAT_TETGEN) {
        rc = st_tetmesh_write_tetgen(m, p, &e);
    } else {
        /* to a temporary file beside the target, renamed when complete */
        st_outfile o;
        rc = st_outfile_begin(&o, p, 0, &e);
        if (!rc) {
            rc = f == ST_TETFORMAT_MSH ? st_tetmesh_write_msh(m, o.tmp, version, binary, &e)
                                       : st_tetmesh_write_medit(m, o.tmp, &e);
            if (rc) {
                if (strcmp(e.file, o.tmp) == 0)
                    snprintf(e.file, sizeof e.file, "%s", p);
                st_outfile_abort(&o);
            } else {
                rc = st_outfile_commit(&o, &e);
            }
        }
    }
    Py_END_ALLOW_THREADS
    PyObject *res = rc ? py_raise(&e, p) : (Py_INCREF(Py_None), Py_None);
    Py_DECREF(path);
    return res;
}

/* ---- module --------------------------------------------------------------- */

static PyObject *py_defaults(PyObject *self, PyObject *noargs)
{
    (void)self;
    (void)noargs;
    st_pipeline_params p = st_pipeline_params_default();
    return Py_BuildValue("{s:n,s:n,s:K,s:d,s:n}", "cells", (Py_ssize_t)p.cells, "tries",
                         (Py_ssize_t)p.tries, "seed", (unsigned long long)p.seed, "offset",
                         p.offset_ratio, "resolution", (Py_ssize_t)ST_DIST_DEFAULT_CELLS);
}

static PyMethodDef methods[] = {
    {"read", py_read, METH_VARARGS, "read(path) -> (V, F)"},
    {"read_parts", py_read_parts, METH_VARARGS, "read_parts(path, mode) -> (V, F, part, names)"},
    {"mesh", (PyCFunction)(void (*)(void))py_mesh, METH_VARARGS | METH_KEYWORDS,
     "mesh(V, F, **params) -> dict"},
    {"distance", (PyCFunction)(void (*)(void))py_distance, METH_VARARGS | METH_KEYWORDS,
     "distance(V, F, resolution, band) -> dict"},
    {"pseudo_volume", (PyCFunction)(void (*)(void))py_pseudo_volume,
     METH_VARARGS | METH_KEYWORDS, "pseudo_volume(V, F, resolution) -> dict"},
    {"write", py_write, METH_VARARGS, "write(mesh_capsule, path, msh_version, binary)"},
    {"library_defaults", py_defaults, METH_NOARGS,
     "the library's pipeline defaults (st_pipeline_params_default)"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef moddef = {PyModuleDef_HEAD_INIT, "souptet._core",
                                    "souptet's C core (libsouptet).", -1, methods,
                                    NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__core(void)
{
    import_array();
    PyObject *mod = PyModule_Create(&moddef);
    if (!mod)
        return NULL;
    py_error = PyErr_NewExceptionWithDoc(
        "souptet.Error",
        "What the souptet library refused or could not do, with its message (a ValueError).\n"
        "Attributes: status (the library's status name), file and line (or None).",
        PyExc_ValueError, NULL);
    py_cancelled = PyErr_NewExceptionWithDoc(
        "souptet.Cancelled", "A run stopped because its souptet.Cancel was set.",
        PyExc_Exception, NULL);
    if (PyType_Ready(&CancelType) < 0 || !py_cancelled ||
        PyModule_AddObject(mod, "Cancel", (Py_INCREF(&CancelType), (PyObject *)&CancelType)) ||
        PyModule_AddObject(mod, "Cancelled", (Py_INCREF(py_cancelled), py_cancelled))) {
        Py_DECREF(mod);
        return NULL;
    }
    if (!py_error || PyModule_AddObject(mod, "Error", (Py_INCREF(py_error), py_error)) ||
        PyModule_AddStringConstant(mod, "version", SOUPTET_VERSION)) {
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
