/*
 * outfile.h - output that appears whole or not at all.
 *
 * Units: none: paths and bytes.
 * Ownership: st_outfile_begin's stream and temporary are the st_outfile's
 * until commit or abort.
 * Threads: the list of temporaries in flight is shared by the process
 * (async-signal-safe to read); begin and commit from one thread at a time.
 * Errors: ST_EIO (naming the path and the reason; also a target that is not
 * a regular file), ST_ENOMEM.
 *
 * st_outfile_begin creates a temporary file beside the target (same
 * directory, so the final rename is atomic); st_outfile_commit checks every
 * write, closes, and renames it over the target; st_outfile_abort removes
 * it. "-" (or NULL) means stdout, where nothing is renamed. A target that
 * exists and is not a regular file (a directory, a device such as
 * /dev/null, a FIFO) is refused: renaming over it would replace the node.
 *
 * Temporary names in flight are remembered so a tool's signal handler can
 * remove them with st_outfile_unlink_pending(), which is async-signal-safe.
 *
 * A temporary is "dir/.NAME.tmp-PID@HOST.XXXXXX": hidden, beside its
 * target NAME, with the pid and machine of the process writing it. One
 * that SIGKILL or a crash left behind (no handler runs) is therefore
 * recognisably stale; st_outfile_begin removes those of its target whose
 * process is gone (same HOST, no such PID), so a rerun cleans up.
 */
#ifndef SOUPTET_OUTFILE_H
#define SOUPTET_OUTFILE_H

#include <stdio.h>
#include "souptet/err.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_outfile {
    char *path;      /* target path; NULL for stdout */
    char *tmp;       /* temporary path being written; NULL for stdout */
    FILE *fp;        /* open stream on tmp (or stdout) when requested */
    int slot;        /* index in the pending list, -1 if none */
} st_outfile;

/* Start an output. With open_stream, o->fp is open for binary writing
 * (stdout for "-"); without, the empty temporary file exists at o->tmp for
 * a library that writes by name (VTK, OpenVDB). Errors name the target.
 * The temporary is listed for st_outfile_unlink_pending before it is
 * created, so a signal never finds one on disk but not in the list. */
st_status st_outfile_begin(st_outfile *o, const char *path, int open_stream,
                           st_error *err);
/* Flush, fsync and close (checking for write errors, earlier ones too,
 * with their errno), then rename tmp to path and fsync path's directory,
 * so the new file survives a power cut once this returns. On failure
 * before the rename the temporary file is removed; a failed directory
 * sync after it is reported (ST_EIO) with the file in place. For stdout,
 * flush it and check its error flag ("<stdout>: write failed: why"). */
st_status st_outfile_commit(st_outfile *o, st_error *err);
/* Close and remove the temporary file. Safe after commit and on a zeroed
 * st_outfile. */
void st_outfile_abort(st_outfile *o);

/* The target path of a temporary name st_outfile_begin made (the same
 * directory, NAME without the leading '.' and the ".tmp-PID@HOST.XXXXXX"
 * tail), malloc'd; NULL when tmp is not such a name (or out of memory). */
char *st_outfile_target_of(const char *tmp);

/* Unlink every temporary file still in flight; async-signal-safe. */
void st_outfile_unlink_pending(void);

/* 1 when path names stdout ("-" or NULL). */
int st_path_is_stdio(const char *path);

#ifdef __cplusplus
}
#endif
#endif
