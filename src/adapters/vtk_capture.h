/*
 * vtk_capture.h - VTK's messages into st_error, and C++ exceptions out of
 * the C API: what the VTK adapters (gridio_vti.cpp, tetio_vtu.cpp) share.
 * C++ only, private to src/adapters/.
 *
 * VTK reports problems through its global output window and its logger,
 * both of which print to stderr; the library must not print. On first use
 * one collecting window is installed in front of whatever window is there:
 * while a Capture is alive on a thread, the errors VTK reports on that
 * thread are collected (thread-locally, so two threads reading two files
 * do not get each other's messages) and nothing is shown; every other
 * message goes on to the window that was there before, unless that was
 * VTK's default window, which would print: then it is dropped and the
 * logger's stderr output is turned off too (file and callback sinks are
 * untouched). This is process-wide VTK state: any other VTK user in the
 * program gets the same silence.
 */
#ifndef SOUPTET_VTK_CAPTURE_H
#define SOUPTET_VTK_CAPTURE_H

#include "souptet/err.h"

#include <exception>
#include <new>
#include <string>

namespace st_vtk {

/* Install the collecting window (once; thread-safe). */
void install();

/* While alive: VTK's errors on this thread are collected. The outermost
 * Capture on a thread starts with nothing collected. */
struct Capture {
    Capture();
    ~Capture();
    Capture(const Capture &) = delete;
    Capture &operator=(const Capture &) = delete;
};

/* Whether VTK reported an error on this thread in the current Capture. */
bool failed();

/* The errors VTK reported, without "ERROR: In FILE, line N" headers,
 * "ClassName (0x...): " prefixes and the executive's "returned failure"
 * dumps, joined by "; ", at most about 400 characters. */
std::string message();

/* st_error_set(err, ST_EINPUT, name, 0, "what: VTK's message"). */
st_status fail(const char *name, const char *what, st_error *err);

/* Run f (returning st_status) with the window installed, every exception
 * turned into an st_error naming name: std::bad_alloc is ST_ENOMEM,
 * another std::exception ST_EINPUT, anything else ST_EINTERNAL. */
template <class F>
st_status guarded(const char *name, const char *what, st_error *err, F &&f)
{
    try {
        install();
        return f();
    } catch (const std::bad_alloc &) {
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory %s",
                            what);
    } catch (const std::exception &e) {
        return st_error_set(err, ST_EINPUT, name, 0, "error %s: %s", what,
                            e.what());
    } catch (...) {
        return st_error_set(err, ST_EINTERNAL, name, 0,
                            "unknown exception %s", what);
    }
}

} // namespace st_vtk

#endif
