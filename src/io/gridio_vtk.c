/*
 * gridio_vtk.c - the VTK adapters' library, opened on first use, and the
 * program's side of the .vti functions and VTK's inflate: each forwards
 * to the plugin's function of the same name (see gridio_internal.h).
 *
 * dlopen finds ST_VTK_PLUGIN through the caller's RUNPATH: the tools',
 * tests' and benches' $ORIGIN/.. (the build tree) and $ORIGIN/../lib
 * (installed), libsouptet-io.so's $ORIGIN; then LD_LIBRARY_PATH and the
 * system's directories. Where a sanitizer's dlopen stands between (ASan
 * and TSan intercept it, and the loader then reads the runtime's RUNPATH,
 * not the caller's), the same places are tried by path: the folder of
 * the object holding this file (dladdr, through links as $ORIGIN is;
 * the program's own path from /proc/self/exe where it was run by name),
 * its parent, and the parent's lib.
 */
#define _GNU_SOURCE /* dladdr */
#include "souptet/gridio.h"
#include "souptet/outfile.h"
#include "../adapters/gridio_internal.h"
#include "vtkxml.h"
#include "../base/fileio.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static pthread_once_t plugin_once = PTHREAD_ONCE_INIT;
static const st_vtk_plugin *plugin;
static char plugin_why[512];

/* ST_VTK_PLUGIN by path, beside the object that holds plugin_open: its
 * folder, then "..", then "../lib" (the RUNPATHs above); NULL if none. */
static void *plugin_beside(void)
{
    static const char *const rel[] = {"/", "/../", "/../lib/"};
    Dl_info info;
    char exe[PATH_MAX];
    if (!dladdr((void *)&plugin_beside, &info) || !info.dli_fname)
        return NULL;
    /* The object's real path, as $ORIGIN is (through links); for the
     * program run by name through PATH dladdr gives argv[0], no folder. */
    const char *obj = exe;
    if (strchr(info.dli_fname, '/')) {
        if (!realpath(info.dli_fname, exe))
            return NULL;
    } else {
        ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (len <= 0)
            return NULL;
        exe[len] = '\0';
    }
    const char *slash = strrchr(obj, '/');
    if (!slash)
        return NULL;
    const int dir = (int)(slash - obj);
    for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++) {
        char path[4096];
        int n = snprintf(path, sizeof path, "%.*s%s%s", dir, obj, rel[i], ST_VTK_PLUGIN);
        void *h = n > 0 && (size_t)n < sizeof path ? dlopen(path, RTLD_NOW | RTLD_LOCAL) : NULL;
        if (h)
            return h;
    }
    return NULL;
}

static void plugin_open(void)
{
    void *h = dlopen(ST_VTK_PLUGIN, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        /* keep the name lookup's reason: it is the one a user can act on */
        const char *e = dlerror();
        snprintf(plugin_why, sizeof plugin_why, "%s", e ? e : "not found");
        h = plugin_beside();
    }
    if (!h)
        return;
    const st_vtk_plugin *(*entry)(void);
    /* POSIX's way from dlsym's object pointer to a function pointer. */
    *(void **)&entry = dlsym(h, "st_vtk_plugin_entry");
    const st_vtk_plugin *p = entry ? entry() : NULL;
    if (!p || p->size != sizeof *p || strcmp(p->version, SOUPTET_VERSION) != 0) {
        snprintf(plugin_why, sizeof plugin_why, "it is not souptet %s's (%s)",
                 SOUPTET_VERSION, p ? p->version : "no st_vtk_plugin_entry");
        dlclose(h);
        return;
    }
    plugin = p;
}

st_status st_vtk_plugin_get(const st_vtk_plugin **out, const char *name, st_error *err)
{
    pthread_once(&plugin_once, plugin_open);
    *out = plugin;
    if (!plugin)
        return st_error_set(err, ST_EIO, name, 0,
                            "VTK files need %s, which cannot be loaded: %s",
                            ST_VTK_PLUGIN, plugin_why);
    return ST_OK;
}

st_status st_grid_write_vti(const st_grid *g, const char *path, st_error *err)
{
    ST_VTK_FORWARD(path, err, grid_write_vti(g, path, err));
}

st_status st_grid_read_vti(st_grid **out, const char *path, size_t max_bytes, st_error *err)
{
    *out = NULL;
    ST_VTK_FORWARD(st_path_is_stdio(path) ? ST_STDIN_NAME : path, err,
                   grid_read_vti(out, path, max_bytes, err));
}

st_status st_gridio_read_vti_mem(st_grid **out, const unsigned char *data, size_t size,
                                 const char *name, size_t max_bytes, st_error *err)
{
    *out = NULL;
    ST_VTK_FORWARD(name, err, grid_read_vti_mem(out, data, size, name, max_bytes, err));
}

size_t st_vtkxml_inflate_vtk(void *user, const char *compressor, const unsigned char *in,
                             size_t n, unsigned char *out, size_t cap)
{
    const st_vtk_plugin *p;
    if (st_vtk_plugin_get(&p, compressor, NULL) != ST_OK)
        return 0;
    return p->inflate(user, compressor, in, n, out, cap);
}
