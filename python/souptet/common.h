/*
 * common.h - what both extension modules (_core.c, _io.c) share: numpy
 * arrays to a soup, library errors to Python exceptions, and Ctrl-C as
 * the library's cancel flag (progress.h). Static functions: each module
 * includes it once.
 */
#ifndef SOUPTET_PY_COMMON_H
#define SOUPTET_PY_COMMON_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "souptet/err.h"
#include "souptet/progress.h"
#include "souptet/soup.h"

/* souptet.Error (a ValueError), created by _core and borrowed by _io. */
static PyObject *py_error;

/* Raise the exception for a library error: MemoryError for ST_ENOMEM,
 * OSError (errno, message, filename) for ST_EIO, KeyboardInterrupt for
 * ST_ECANCELLED, souptet.Error otherwise, with attributes status (the
 * status's name), file and line. path: the file a call was given (for
 * OSError's filename and errno), may be NULL. Returns NULL. */
static PyObject *py_raise(const st_error *e, const char *path)
{
    char buf[1200];
    st_error_format(e, buf, sizeof buf);
    switch (e->status) {
    case ST_ENOMEM:
        PyErr_SetString(PyExc_MemoryError, buf);
        return NULL;
    case ST_ECANCELLED:
        PyErr_SetNone(PyExc_KeyboardInterrupt);
        return NULL;
    case ST_EIO: {
        const char *file = e->file[0] ? e->file : path;
        int en = EIO;
        struct stat sb;
        if (file && stat(file, &sb) != 0)
            en = errno;
        else if (file && S_ISDIR(sb.st_mode))
            en = EISDIR;
        else if (file && access(file, R_OK) != 0)
            en = errno;
        PyObject *fn = file ? PyUnicode_DecodeFSDefault(file) : (Py_INCREF(Py_None), Py_None);
        if (!fn)
            return NULL;
        PyObject *exc = PyObject_CallFunction(PyExc_OSError, "isO", en, buf, fn);
        Py_DECREF(fn);
        if (exc) {
            PyErr_SetObject((PyObject *)Py_TYPE(exc), exc);
            Py_DECREF(exc);
        }
        return NULL;
    }
    default: {
        PyObject *exc = PyObject_CallFunction(py_error, "s", buf);
        if (!exc)
            return NULL;
        PyObject *st = PyUnicode_FromString(st_status_name(e->status));
        PyObject *file = e->file[0] ? PyUnicode_DecodeFSDefault(e->file)
                                    : (Py_INCREF(Py_None), Py_None);
        PyObject *line = e->line ? PyLong_FromLongLong(e->line) : (Py_INCREF(Py_None), Py_None);
        if (st && file && line) {
            PyObject_SetAttrString(exc, "status", st);
            PyObject_SetAttrString(exc, "file", file);
            PyObject_SetAttrString(exc, "line", line);
        }
        Py_XDECREF(st);
        Py_XDECREF(file);
        Py_XDECREF(line);
        PyErr_SetObject(py_error, exc);
        Py_DECREF(exc);
        return NULL;
    }
    }
}

/* souptet.Error with a printf-style message; returns NULL. */
static PyObject *py_fail(const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    PyErr_SetString(py_error, buf);
    return NULL;
}

/* The current exception's text, replaced by souptet.Error(what: text). */
static PyObject *py_rewrap(const char *what)
{
    PyObject *type, *value, *tb;
    PyErr_Fetch(&type, &value, &tb);
    PyErr_NormalizeException(&type, &value, &tb);
    PyObject *s = value ? PyObject_Str(value) : NULL;
    const char *txt = s ? PyUnicode_AsUTF8(s) : NULL;
    PyErr_Clear();
    py_fail("%s%s%s", what, txt ? ": " : "", txt ? txt : "");
    Py_XDECREF(s);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(tb);
    return NULL;
}

/* An (n, 3) array of numbers (not bool, not complex) from any object, as
 * the dtype it has; NULL with souptet.Error set otherwise. */
static PyArrayObject *py_array_n3(PyObject *o, const char *name, const char *kinds)
{
    PyArrayObject *a = (PyArrayObject *)PyArray_FROM_O(o);
    if (!a) {
        char what[64];
        snprintf(what, sizeof what, "%s must be an (n, 3) array of numbers", name);
        return (PyArrayObject *)py_rewrap(what);
    }
    char kind = PyArray_DESCR(a)->kind;
    if (!strchr(kinds, kind)) {
        PyObject *dt = PyObject_Str((PyObject *)PyArray_DESCR(a));
        py_fail("%s must be %s, not %s", name,
                strchr(kinds, 'f') ? "numbers (float or integer)"
                                   : "integers (vertex indices); F.astype(int) converts",
                dt ? PyUnicode_AsUTF8(dt) : "?");
        Py_XDECREF(dt);
        Py_DECREF(a);
        return NULL;
    }
    if (PyArray_NDIM(a) != 2 || PyArray_DIM(a, 1) != 3) {
        char shape[128] = "(";
        for (int i = 0; i < PyArray_NDIM(a); i++)
            snprintf(shape + strlen(shape), sizeof shape - strlen(shape), "%s%zd",
                     i ? ", " : "", (Py_ssize_t)PyArray_DIM(a, i));
        snprintf(shape + strlen(shape), sizeof shape - strlen(shape), ")");
        py_fail("%s must have shape (n, 3), not %s", name, shape);
        Py_DECREF(a);
        return NULL;
    }
    if (PyArray_DIM(a, 0) == 0) {
        py_fail("%s is empty: %s", name,
                strchr(kinds, 'f') ? "no vertices" : "no triangles");
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

/* A soup from V ((n, 3) numbers, finite) and F ((m, 3) integers in
 * [0, n)); every row of V a vertex (in order: embed_tet follows V), every
 * row of F a triangle. 0, or -1 with an exception set. */
static int py_soup(PyObject *V, PyObject *F, st_soup **out)
{
    *out = NULL;
    PyArrayObject *v0 = NULL, *f0 = NULL, *v = NULL, *f = NULL;
    st_soup *s = NULL;
    int rc = -1;
    if (!(v0 = py_array_n3(V, "V", "iuf")) || !(f0 = py_array_n3(F, "F", "iu")))
        goto done;
    v = (PyArrayObject *)PyArray_FROM_OTF((PyObject *)v0, NPY_FLOAT64,
                                          NPY_ARRAY_IN_ARRAY | NPY_ARRAY_FORCECAST);
    int big_unsigned = PyArray_DESCR(f0)->kind == 'u' && PyArray_ITEMSIZE(f0) >= 8;
    f = (PyArrayObject *)PyArray_FROM_OTF((PyObject *)f0, big_unsigned ? NPY_UINT64 : NPY_INT64,
                                          NPY_ARRAY_IN_ARRAY);
    if (!v || !f)
        goto done;
    const npy_intp n = PyArray_DIM(v, 0), m = PyArray_DIM(f, 0);
    if ((uint64_t)n > UINT32_MAX) {
        py_fail("V has %zd vertices, more than the library's %u", (Py_ssize_t)n, UINT32_MAX);
        goto done;
    }
    const double *x = PyArray_DATA(v);
    for (npy_intp i = 0; i < 3 * n; i++)
        if (!isfinite(x[i])) {
            py_fail("V[%zd] = (%g, %g, %g) is not finite", (Py_ssize_t)(i / 3),
                    x[i / 3 * 3], x[i / 3 * 3 + 1], x[i / 3 * 3 + 2]);
            goto done;
        }
    if (big_unsigned) {
        const uint64_t *t = PyArray_DATA(f);
        for (npy_intp i = 0; i < 3 * m; i++)
            if (t[i] >= (uint64_t)n) {
                py_fail("F[%zd, %d] = %llu is out of range: V has %zd rows",
                        (Py_ssize_t)(i / 3), (int)(i % 3), (unsigned long long)t[i],
                        (Py_ssize_t)n);
                goto done;
            }
    } else {
        const int64_t *t = PyArray_DATA(f);
        for (npy_intp i = 0; i < 3 * m; i++)
            if (t[i] < 0 || t[i] >= (int64_t)n) {
                py_fail("F[%zd, %d] = %lld is %s: V has %zd rows", (Py_ssize_t)(i / 3),
                        (int)(i % 3), (long long)t[i],
                        t[i] < 0 ? "negative" : "out of range", (Py_ssize_t)n);
                goto done;
            }
    }
    st_error e;
    st_error_clear(&e);
    if (!(s = st_soup_new())) {
        PyErr_NoMemory();
        goto done;
    }
    for (npy_intp i = 0; i < n; i++)
        if (st_soup_add_vertex(s, x[3 * i], x[3 * i + 1], x[3 * i + 2], &e)) {
            py_raise(&e, NULL);
            goto done;
        }
    for (npy_intp i = 0; i < m; i++) {
        uint32_t a, b, c;
        if (big_unsigned) {
            const uint64_t *t = (const uint64_t *)PyArray_DATA(f) + 3 * i;
            a = (uint32_t)t[0], b = (uint32_t)t[1], c = (uint32_t)t[2];
        } else {
            const int64_t *t = (const int64_t *)PyArray_DATA(f) + 3 * i;
            a = (uint32_t)t[0], b = (uint32_t)t[1], c = (uint32_t)t[2];
        }
        if (st_soup_add_triangle(s, a, b, c, &e)) {
            py_raise(&e, NULL);
            goto done;
        }
    }
    *out = s;
    s = NULL;
    rc = 0;
done:
    st_soup_free(s);
    Py_XDECREF(v0);
    Py_XDECREF(f0);
    Py_XDECREF(v);
    Py_XDECREF(f);
    return rc;
}

/* 80% of the physical memory, as the tools' --max-memory default. */
static size_t py_max_bytes(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (size_t)((double)pages * (double)size * 0.8) : 0;
}

/* ---- Ctrl-C ---------------------------------------------------------------
 * While a long call runs in the main thread with the GIL released, SIGINT
 * goes to a C handler that sets the call's cancel flag (async-signal-safe,
 * progress.h) and then hands the signal on to the handler it replaced
 * (Python's, which records it for PyErr_CheckSignals). Only the main
 * thread installs it, only over a handler that is a function (not SIG_IGN
 * or SIG_DFL), and never twice at once (a progress callable that calls
 * back into souptet). */
static volatile int *volatile py_sig_flag;
static volatile sig_atomic_t py_sig_seen;
static struct sigaction py_sig_old;
static int py_sig_depth;

static void py_sig_handler(int sig, siginfo_t *info, void *uc)
{
    py_sig_seen = 1;
    volatile int *flag = py_sig_flag;
    if (flag)
        st_progress_cancel(flag);
    if (py_sig_old.sa_flags & SA_SIGINFO) {
        if (py_sig_old.sa_sigaction)
            py_sig_old.sa_sigaction(sig, info, uc);
    } else if (py_sig_old.sa_handler != SIG_DFL && py_sig_old.sa_handler != SIG_IGN) {
        py_sig_old.sa_handler(sig);
    }
}

static int py_is_main_thread(void)
{
    PyObject *threading = PyImport_ImportModule("threading");
    if (!threading) {
        PyErr_Clear();
        return 0;
    }
    PyObject *mt = PyObject_CallMethod(threading, "main_thread", NULL);
    PyObject *ident = mt ? PyObject_GetAttrString(mt, "ident") : NULL;
    int main = 0;
    if (ident)
        main = PyLong_AsUnsignedLong(ident) == PyThread_get_thread_ident();
    PyErr_Clear();
    Py_XDECREF(ident);
    Py_XDECREF(mt);
    Py_DECREF(threading);
    return main;
}

/* Call with the GIL held, before releasing it; returns whether the
 * handler went in (pass that to py_sig_end). */
static int py_sig_begin(volatile int *flag)
{
    if (py_sig_depth || !py_is_main_thread())
        return 0;
    struct sigaction cur;
    if (sigaction(SIGINT, NULL, &cur) != 0)
        return 0;
    if (!(cur.sa_flags & SA_SIGINFO) && (cur.sa_handler == SIG_DFL || cur.sa_handler == SIG_IGN))
        return 0;
    py_sig_old = cur;
    py_sig_seen = 0;
    py_sig_flag = flag;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = py_sig_handler;
    sa.sa_flags = SA_SIGINFO | SA_ONSTACK;
    sigemptyset(&sa.sa_mask);
    if (sigaction(SIGINT, &sa, NULL) != 0) {
        py_sig_flag = NULL;
        return 0;
    }
    py_sig_depth = 1;
    return 1;
}

/* With the GIL held again: put the old handler back. Returns -1 with an
 * exception set when a SIGINT came (what Python's handler raises, or
 * KeyboardInterrupt), else 0. */
static int py_sig_end(int installed)
{
    if (!installed)
        return 0;
    sigaction(SIGINT, &py_sig_old, NULL);
    py_sig_flag = NULL;
    py_sig_depth = 0;
    if (!py_sig_seen)
        return 0;
    py_sig_seen = 0;
    if (PyErr_CheckSignals() < 0)
        return -1;
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    return -1;
}

#endif
