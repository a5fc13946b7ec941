#define _POSIX_C_SOURCE 200809L
#include "outfile.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int lod_outfile_open(lod_outfile *o, const char *path, char *err, size_t err_len)
{
    size_t n = strlen(path) + 16;
    o->f = NULL;
    o->path = strdup(path);
    o->tmp = malloc(n);
    if (!o->path || !o->tmp) {
        free(o->path);
        free(o->tmp);
        snprintf(err, err_len, "%s: out of memory", path);
        return -1;
    }
    snprintf(o->tmp, n, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(o->tmp);
    if (fd >= 0 && !(o->f = fdopen(fd, "wb"))) close(fd);
    if (!o->f) {
        snprintf(err, err_len, "cannot write %s: %s", path, strerror(errno));
        if (fd >= 0) unlink(o->tmp);
        free(o->path);
        free(o->tmp);
        return -1;
    }
    return 0;
}

int lod_outfile_close(lod_outfile *o, int ok, char *err, size_t err_len)
{
    int saved = 0;
    if (ok && (ferror(o->f) || fflush(o->f) != 0 || fsync(fileno(o->f)) != 0)) { ok = 0; saved = errno; }
    if (fclose(o->f) != 0 && ok) { ok = 0; saved = errno; }
    if (ok && rename(o->tmp, o->path) != 0) { ok = 0; saved = errno; }
    if (!ok) {
        unlink(o->tmp);
        snprintf(err, err_len, "cannot write %s: %s", o->path, saved ? strerror(saved) : "not finished");
    }
    free(o->path);
    free(o->tmp);
    o->f = NULL;
    return ok ? 0 : -1;
}
