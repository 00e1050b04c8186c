/* err.c - error records (see err.h). */
#include "souptet/err.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void st_error_clear(st_error *err)
{
    if (!err)
        return;
    err->status = ST_OK;
    err->file[0] = '\0';
    err->line = 0;
    err->offset = -1;
    err->msg[0] = '\0';
}

#ifdef __GNUC__
__attribute__((format(printf, 6, 0)))
#endif
static st_status set_va(st_error *err, st_status status, const char *file,
                        long long line, long long offset, const char *fmt,
                        va_list ap)
{
    if (!err)
        return status;
    err->status = status;
    snprintf(err->file, sizeof err->file, "%s", file ? file : "");
    err->line = line;
    err->offset = offset;
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    return status;
}

st_status st_error_set(st_error *err, st_status status, const char *file,
                       long long line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    st_status s = set_va(err, status, file, line, -1, fmt, ap);
    va_end(ap);
    return s;
}

st_status st_error_set_offset(st_error *err, st_status status,
                              const char *file, long long offset,
                              const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    st_status s = set_va(err, status, file, 0, offset, fmt, ap);
    va_end(ap);
    return s;
}

char *st_error_format(const st_error *err, char *buf, size_t n)
{
    if (n == 0)
        return buf;
    if (!err) {
        buf[0] = '\0';
        return buf;
    }
    if (err->file[0] && err->line > 0)
        snprintf(buf, n, "%s:%lld: %s", err->file, err->line, err->msg);
    else if (err->file[0] && err->offset >= 0)
        snprintf(buf, n, "%s: byte %lld: %s", err->file, err->offset,
                 err->msg);
    else if (err->file[0])
        snprintf(buf, n, "%s: %s", err->file, err->msg);
    else
        snprintf(buf, n, "%s", err->msg);
    return buf;
}

const char *st_status_name(st_status status)
{
    switch (status) {
    case ST_OK: return "ok";
    case ST_EINPUT: return "bad input";
    case ST_EIO: return "I/O error";
    case ST_ENOMEM: return "out of memory";
    case ST_ELIMIT: return "over limit";
    case ST_EINTERNAL: return "internal error";
    case ST_ECANCELLED: return "cancelled";
    }
    return "unknown status";
}
