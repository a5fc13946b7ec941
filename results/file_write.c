#define _POSIX_C_SOURCE 200809L
#include "results/file_write.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* dirname() may modify its argument and may return static storage: work on a copy. */
static char *folder_of(const char *path)
{
    char *copy = strdup(path);
    if (!copy) return NULL;
    char *dir = strdup(dirname(copy));
    free(copy);
    return dir;
}

static void release(csf_atomic_file *af)
{
    free(af->path);
    free(af->tmp_path);
    af->path = af->tmp_path = NULL;
    af->fp = NULL;
}

csf_status csf_atomic_open(csf_atomic_file *af, const char *path, const char *what, csf_error *err)
{
    memset(af, 0, sizeof *af);
    af->what = what;
    if (!path || !*path) return csf_error_set(err, CSF_E_INVALID_ARG, "no path given for the %s", what);
    char *dir = folder_of(path);
    char *copy = strdup(path);
    af->path = strdup(path);
    if (!dir || !copy || !af->path) {
        free(dir);
        free(copy);
        release(af);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    /* A hidden name in the same folder: rename() is atomic only within one file system. */
    const char *base = basename(copy);
    size_t n = strlen(dir) + strlen(base) + 16;
    af->tmp_path = malloc(n);
    if (!af->tmp_path) {
        free(dir);
        free(copy);
        release(af);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    snprintf(af->tmp_path, n, "%s/.%s.XXXXXX", dir, base);
    free(copy);
    int fd = mkstemp(af->tmp_path);
    if (fd < 0) {
        csf_status st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: cannot create a file in %s: %s",
                                      what, path, dir, strerror(errno));
        free(dir);
        release(af);
        return st;
    }
    free(dir);
    /* mkstemp makes the file 0600; an output file gets the permissions the umask allows. */
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(fd, 0666 & ~mask);
    af->fp = fdopen(fd, "wb");
    if (!af->fp) {
        int e = errno;
        close(fd);
        unlink(af->tmp_path);
        release(af);
        return csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", what, path, strerror(e));
    }
    return CSF_OK;
}

static void sync_folder(const char *path)
{
    char *dir = folder_of(path);
    if (!dir) return;
    int fd = open(dir, O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        (void)fsync(fd); /* some file systems refuse fsync on a folder: the rename still stands */
        close(fd);
    }
    free(dir);
}

csf_status csf_atomic_commit(csf_atomic_file *af, csf_error *err)
{
    if (!af->fp) return csf_error_set(err, CSF_E_INVALID_ARG, "no open %s to commit", af->what);
    int e = 0;
    if (ferror(af->fp)) e = errno ? errno : EIO;
    if (!e && fflush(af->fp) != 0) e = errno;
    if (!e && fsync(fileno(af->fp)) != 0) e = errno;
    if (fclose(af->fp) != 0 && !e) e = errno;
    af->fp = NULL;
    if (!e && rename(af->tmp_path, af->path) != 0) e = errno;
    if (e) {
        unlink(af->tmp_path);
        csf_status st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", af->what, af->path,
                                      strerror(e));
        release(af);
        return st;
    }
    sync_folder(af->path);
    release(af);
    return CSF_OK;
}

void csf_atomic_abort(csf_atomic_file *af)
{
    if (af->fp) fclose(af->fp);
    if (af->tmp_path) unlink(af->tmp_path);
    release(af);
}

csf_status csf_write_file_atomic(const char *path, const char *what, const void *buf, size_t len,
                                 csf_error *err)
{
    csf_atomic_file af;
    csf_status st = csf_atomic_open(&af, path, what, err);
    if (st) return st;
    if (len && fwrite(buf, 1, len, af.fp) != len) {
        int e = errno ? errno : EIO;
        csf_atomic_abort(&af);
        return csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", what, path, strerror(e));
    }
    return csf_atomic_commit(&af, err);
}

csf_status csf_check_output_path(const char *path, const char *what, csf_error *err)
{
    if (!path || !*path) return csf_error_set(err, CSF_E_INVALID_ARG, "no path given for the %s", what);
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s %s is a folder, not a file", what, path);
    char *dir = folder_of(path);
    if (!dir) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    csf_status st = CSF_OK;
    if (stat(dir, &sb) != 0)
        st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: folder %s: %s", what, path, dir,
                           strerror(errno));
    else if (!S_ISDIR(sb.st_mode))
        st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s is not a folder", what, path, dir);
    else if (access(dir, W_OK | X_OK) != 0)
        st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: folder %s: %s", what, path, dir,
                           strerror(errno));
    free(dir);
    return st;
}
