/*
 * outfile.c - atomic outputs (see outfile.h).
 *
 * The temporary file is created with mkstemp in the target's directory, so
 * rename(2) replaces the target in one step and a crash or a signal never
 * leaves a half-written file under the target's name. Durability: the
 * temporary is fsync'ed before the rename (else after a power cut the
 * rename may be on disk and the data not: an empty or partial file under
 * the target's name) and the directory after it (else the rename itself
 * may be lost).
 */
#include "souptet/outfile.h"
#include "souptet/mem.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef HOST_NAME_MAX
#define HOST_NAME_MAX 255
#endif

/* Temporary paths in flight, for st_outfile_unlink_pending. A tool has at
 * most a few outputs open at once. The signal handler only reads them. */
#define PENDING_MAX 16
static char *volatile pending[PENDING_MAX];

int st_path_is_stdio(const char *path)
{
    return path == NULL || strcmp(path, "-") == 0;
}

static int pending_add(char *tmp)
{
    for (int i = 0; i < PENDING_MAX; i++)
        if (!pending[i]) {
            pending[i] = tmp;
            return i;
        }
    return -1;
}

static void pending_remove(int slot)
{
    if (slot >= 0 && slot < PENDING_MAX)
        pending[slot] = NULL;
}

void st_outfile_unlink_pending(void)
{
    for (int i = 0; i < PENDING_MAX; i++) {
        char *p = pending[i];
        if (p)
            unlink(p);
    }
}

/* This machine's name for temporary names: no '/' or '@' (they separate
 * the name's parts), "localhost" when it has none. */
static void host_name(char *buf, size_t n)
{
    if (gethostname(buf, n) != 0)
        buf[0] = '\0';
    buf[n - 1] = '\0';
    for (char *c = buf; *c; c++)
        if (*c == '/' || *c == '@' || *c == '.')
            *c = '_';  /* '.' too: a name is one label, and parses back */
    if (!buf[0])
        snprintf(buf, n, "localhost");
}

/* The temporary name's prefix "dir/.NAME.tmp-" of target path (malloc'd). */
static char *temp_prefix(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;
    size_t base = strlen(path + dirlen);
    char *p = malloc(dirlen + base + 8);
    if (!p)
        return NULL;
    memcpy(p, path, dirlen);
    p[dirlen] = '.';
    memcpy(p + dirlen + 1, path + dirlen, base);
    memcpy(p + dirlen + 1 + base, ".tmp-", 6);
    return p;
}

/* Remove the temporaries of path that a process of this machine left
 * when it died without cleaning up (SIGKILL, a power cut): names
 * "PREFIX<pid>@<host>.XXXXXX" whose pid is not running. A live pid (this
 * process's, another writer's, or a reused one) keeps its file. Best
 * effort: errors are ignored, nothing else is touched. */
static void remove_stale(const char *prefix, const char *host)
{
    const char *slash = strrchr(prefix, '/');
    size_t dirlen = slash ? (size_t)(slash - prefix) + 1 : 0;
    const char *lead = prefix + dirlen;
    size_t leadlen = strlen(lead), hostlen = strlen(host);
    char dir[4096];
    if (dirlen >= sizeof dir)
        return;
    if (dirlen)
        snprintf(dir, sizeof dir, "%.*s", (int)dirlen, prefix);
    else
        snprintf(dir, sizeof dir, ".");
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *n = e->d_name;
        if (strncmp(n, lead, leadlen) != 0)
            continue;
        const char *q = n + leadlen;
        long pid = 0;
        int digits = 0;
        while (*q >= '0' && *q <= '9' && digits < 10) {
            pid = pid * 10 + (*q++ - '0');
            digits++;
        }
        if (!digits || *q++ != '@' || strncmp(q, host, hostlen) != 0)
            continue;
        q += hostlen;
        if (q[0] != '.' || strlen(q) != 7)
            continue;
        if (pid <= 0 || pid == (long)getpid() || pid > INT_MAX)
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;   /* running (or not ours to signal): in use */
        char full[4096 + 256];
        snprintf(full, sizeof full, "%s%s", dirlen ? dir : "", n);
        unlink(full);
    }
    closedir(d);
}

char *st_outfile_target_of(const char *tmp)
{
    if (!tmp)
        return NULL;
    size_t n = strlen(tmp);
    const char *slash = strrchr(tmp, '/');
    size_t dl = slash ? (size_t)(slash - tmp) + 1 : 0;
    /* ".NAME.tmp-PID@HOST.XXXXXX": the last '@' ends the pid. */
    if (n < dl + 1 + 1 + 5 + 1 + 1 + 1 + 7 || tmp[dl] != '.' || tmp[n - 7] != '.')
        return NULL;
    const char *at = NULL;
    for (const char *c = tmp + n - 8; c > tmp + dl; c--)
        if (*c == '@') {
            at = c;
            break;
        }
    if (!at)
        return NULL;
    const char *c = at;
    while (c > tmp + dl && c[-1] >= '0' && c[-1] <= '9')
        c--;
    if (c == at || c - (tmp + dl) < 6 || strncmp(c - 5, ".tmp-", 5) != 0)
        return NULL;
    size_t base = (size_t)(c - 5 - (tmp + dl + 1));
    char *t = malloc(dl + base + 1);
    if (!t)
        return NULL;
    memcpy(t, tmp, dl);
    memcpy(t + dl, tmp + dl + 1, base);
    t[dl + base] = '\0';
    return t;
}

st_status st_outfile_begin(st_outfile *o, const char *path, int open_stream,
                           st_error *err)
{
    memset(o, 0, sizeof *o);
    o->slot = -1;
    if (st_path_is_stdio(path)) {
        if (open_stream)
            o->fp = stdout;
        return ST_OK;
    }
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return st_error_set(err, ST_EIO, path, 0, "is a directory");
    /* The temporary file is renamed over the target: over a device or a
     * FIFO (/dev/null, /dev/stdout) that would replace the node itself. */
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return st_error_set(err, ST_EIO, path, 0, "not a regular file "
                            "(write to '-' for standard output)");
    /* Beside the target, hidden, so a reader never mistakes it for output,
     * and named for what it is and who writes it, so one left behind by a
     * killed process is known for stale: "dir/.NAME.tmp-PID@HOST.XXXXXX". */
    char host[HOST_NAME_MAX + 1], who[HOST_NAME_MAX + 32];
    host_name(host, sizeof host);
    char *prefix = temp_prefix(path);
    /* A long NAME shortens the host (the name must fit in NAME_MAX). */
    const char *slash = strrchr(path, '/');
    size_t used = strlen(slash ? slash + 1 : path) + 6 + 20 + 8;
    if (used + strlen(host) > NAME_MAX)
        host[used < NAME_MAX ? NAME_MAX - used : 0] = '\0';
    snprintf(who, sizeof who, "%ld@%s.XXXXXX", (long)getpid(), host);
    o->path = st_strdup(path);
    o->tmp = prefix ? malloc(strlen(prefix) + strlen(who) + 1) : NULL;
    if (!o->path || !o->tmp) {
        free(prefix);
        st_outfile_abort(o);
        return st_error_set(err, ST_ENOMEM, path, 0, "out of memory");
    }
    remove_stale(prefix, host);
    strcpy(o->tmp, prefix);
    strcat(o->tmp, who);
    free(prefix);
    /* Listed before it exists, so no signal finds it on disk but not in
     * the list (mkstemp fills in the name in place; until then the handler
     * unlinks a name that does not exist). Signals are not blocked here:
     * a blocked main thread would have them delivered to another thread,
     * while this one goes on writing and could re-create the file. */
    o->slot = pending_add(o->tmp);
    int fd = mkstemp(o->tmp);
    if (fd < 0) {
        int e = errno;
        pending_remove(o->slot);
        o->slot = -1;
        free(o->tmp);
        o->tmp = NULL;
        st_outfile_abort(o);
        return st_error_set(err, ST_EIO, path, 0, "cannot create: %s",
                            strerror(e));
    }
    /* mkstemp makes the file 0600; outputs are ordinary files. */
    mode_t mask = umask(0);
    umask(mask);
    fchmod(fd, 0666 & ~mask);
    if (open_stream) {
        o->fp = fdopen(fd, "wb");
        if (!o->fp) {
            int e = errno;
            close(fd);
            st_outfile_abort(o);
            return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                                strerror(e));
        }
    } else {
        close(fd);
    }
    return ST_OK;
}

/* The errno of a stream whose error flag is set: earlier writes may have
 * failed and errno been overwritten since (it then said "write failed:
 * Success"), and glibc does not retry a failed buffer on fflush. So ask
 * the file again: fsync reports errors of writes the kernel accepted, and
 * one more byte at the end fails as the lost write did (ENOSPC, EFBIG,
 * EDQUOT; the temporary is removed afterwards anyway). 0 when the stream
 * is fine. */
static int stream_errno(FILE *fp)
{
    errno = 0;
    if (fflush(fp) != 0 && errno)
        return errno;
    if (!ferror(fp))
        return 0;
    int fd = fileno(fp);
    errno = 0;
    if (fsync(fd) != 0 && errno)
        return errno;
    off_t end = lseek(fd, 0, SEEK_END);
    errno = 0;
    if (end >= 0 && pwrite(fd, "", 1, end) < 0 && errno)
        return errno;
    return EIO;   /* the cause is gone; say "Input/output error" */
}

/* fsync a file by name (written by a library that closed it). */
static int sync_path(const char *path, int dir)
{
    int fd = open(path, O_RDONLY | (dir ? O_DIRECTORY : 0));
    if (fd < 0)
        return errno;
    int e = fsync(fd) != 0 ? errno : 0;
    close(fd);
    /* Some file systems cannot sync a directory: nothing more to do. */
    if (dir && (e == EINVAL || e == EBADF))
        e = 0;
    return e;
}

/* The directory of path ("." when it has none), into buf. */
static void dir_of(char *buf, size_t n, const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(buf, n, ".");
    else if (slash == path)
        snprintf(buf, n, "/");
    else
        snprintf(buf, n, "%.*s", (int)(slash - path), path);
}

st_status st_outfile_commit(st_outfile *o, st_error *err)
{
    if (!o->path) {             /* stdout */
        /* An earlier write may have failed with nothing left to flush. */
        errno = 0;
        if (o->fp && (fflush(o->fp) != 0 || ferror(o->fp))) {
            int e = errno;
            o->fp = NULL;
            return st_error_set(err, ST_EIO, "<stdout>", 0,
                                "write failed: %s",
                                e ? strerror(e) : "I/O error");
        }
        /* A pipe or terminal cannot be synced (EINVAL); a redirected
         * file is not ours to sync either: the shell made it. */
        o->fp = NULL;
        return ST_OK;
    }
    if (o->fp) {
        int e = stream_errno(o->fp);
        if (!e && fsync(fileno(o->fp)) != 0)
            e = errno;
        if (fclose(o->fp) != 0 && !e)
            e = errno ? errno : EIO;
        o->fp = NULL;
        if (e) {
            st_error_set(err, ST_EIO, o->path, 0, "write failed: %s",
                         strerror(e));
            st_outfile_abort(o);
            return ST_EIO;
        }
    } else {
        int e = sync_path(o->tmp, 0);
        if (e) {
            st_error_set(err, ST_EIO, o->path, 0, "write failed: %s",
                         strerror(e));
            st_outfile_abort(o);
            return ST_EIO;
        }
    }
    if (rename(o->tmp, o->path) != 0) {
        int e = errno;
        st_error_set(err, ST_EIO, o->path, 0, "cannot rename into place: %s",
                     strerror(e));
        st_outfile_abort(o);
        return ST_EIO;
    }
    pending_remove(o->slot);
    free(o->tmp);
    o->tmp = NULL;
    o->slot = -1;
    char dir[4096];
    dir_of(dir, sizeof dir, o->path);
    int e = sync_path(dir, 1);
    st_status rc = ST_OK;
    if (e)   /* the file is whole, but its name may not survive a crash */
        rc = st_error_set(err, ST_EIO, o->path, 0, "cannot sync its directory: %s",
                          strerror(e));
    free(o->path);
    o->path = NULL;
    return rc;
}

void st_outfile_abort(st_outfile *o)
{
    if (o->fp && o->fp != stdout)
        fclose(o->fp);
    o->fp = NULL;
    if (o->tmp) {
        unlink(o->tmp);          /* then forget it: a signal between the two */
        pending_remove(o->slot); /* unlinks a name that is already gone */
        free(o->tmp);
    }
    free(o->path);
    o->tmp = o->path = NULL;
    o->slot = -1;
}
