#define _POSIX_C_SOURCE 200809L
#include "core/file_write.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
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
    af->through = 0;
}

/* "-", /dev/stdout, /dev/stderr, /dev/fd/N and /proc/self/fd/N name a descriptor this process
 * already has, as they do in a shell redirection: writing through a duplicate keeps the shell's
 * offset and append mode (a fresh open of /proc/self/fd/1 would start at byte 0 of a log that
 * is being appended to). Returns the descriptor, or -1 when path names none. */
static int descriptor_alias(const char *path)
{
    if (!strcmp(path, "-") || !strcmp(path, "/dev/stdout")) return STDOUT_FILENO;
    if (!strcmp(path, "/dev/stderr")) return STDERR_FILENO;
    const char *num = NULL;
    if (!strncmp(path, "/dev/fd/", 8)) num = path + 8;
    else if (!strncmp(path, "/proc/self/fd/", 14)) num = path + 14;
    if (!num || !*num) return -1;
    char *end;
    errno = 0;
    long fd = strtol(num, &end, 10);
    if (*end || errno || fd < 0 || fd > INT_MAX) return -1;
    return (int)fd;
}

/* What an existing destination is, and so how it is written. */
typedef enum {
    DEST_NEW,      /* nothing there: created, with the permissions the umask allows */
    DEST_REPLACE,  /* a regular file: a temporary beside it is renamed over it */
    DEST_THROUGH,  /* a device or FIFO: opened and written in place, never replaced */
} dest_kind;

/* Classifies path, following symbolic links: a link to a regular file has its target replaced
 * (the link stays a link); a link that points nowhere is refused rather than followed into a
 * file of the link's choosing. *real receives the file to replace (path itself, or the link's
 * resolved target). Devices other than character devices and FIFOs, sockets and folders are
 * refused: a report written over a disk is never what was meant. */
static csf_status classify(const char *path, const char *what, dest_kind *kind, char **real,
                           struct stat *sb, csf_error *err)
{
    *real = NULL;
    struct stat lsb;
    if (lstat(path, &lsb) != 0) {
        if (errno != ENOENT)
            return csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", what, path, strerror(errno));
        *kind = DEST_NEW;
        *real = strdup(path);
        return *real ? CSF_OK : csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    *sb = lsb;
    if (S_ISLNK(lsb.st_mode) && stat(path, sb) != 0)
        return csf_error_set(err, CSF_E_IO, "cannot write %s %s: it is a symbolic link to a file "
                             "that does not exist (%s); csfcal follows links only to existing "
                             "files", what, path, strerror(errno));
    if (S_ISDIR(sb->st_mode))
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s %s is a folder, not a file", what, path);
    if (S_ISCHR(sb->st_mode) || S_ISFIFO(sb->st_mode)) {
        *kind = DEST_THROUGH;
        *real = strdup(path);
        return *real ? CSF_OK : csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    if (!S_ISREG(sb->st_mode))
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s %s is %s, not a file, a character "
                             "device or a FIFO; refusing to write to it", what, path,
                             S_ISBLK(sb->st_mode) ? "a block device" : "a socket");
    *kind = DEST_REPLACE;
    *real = S_ISLNK(lsb.st_mode) ? realpath(path, NULL) : strdup(path);
    if (!*real)
        return csf_error_set(err, CSF_E_IO, "cannot write %s %s: cannot resolve its link: %s",
                             what, path, strerror(errno));
    return CSF_OK;
}

/* Opens a device, FIFO or descriptor alias for writing in place. */
static csf_status open_through(csf_atomic_file *af, const char *path, int alias_fd, csf_error *err)
{
    int fd = alias_fd >= 0 ? fcntl(alias_fd, F_DUPFD_CLOEXEC, 3)
                           : open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        csf_status st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", af->what, path,
                                      strerror(errno));
        release(af);
        return st;
    }
    af->fp = fdopen(fd, "wb");
    if (!af->fp) {
        int e = errno;
        close(fd);
        release(af);
        return csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", af->what, path, strerror(e));
    }
    af->through = 1;
    return CSF_OK;
}

/* A hidden temporary in the destination's folder (rename() is atomic only within one file
 * system), with the mode of the file it replaces or, for a new file, what the umask allows. */
static csf_status open_temporary(csf_atomic_file *af, dest_kind kind, const struct stat *old,
                                 csf_error *err)
{
    char *dir = folder_of(af->path), *copy = strdup(af->path);
    size_t n = dir && copy ? strlen(dir) + strlen(af->path) + 16 : 0;
    af->tmp_path = n ? malloc(n) : NULL;
    if (!af->tmp_path) {
        free(dir);
        free(copy);
        release(af);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    snprintf(af->tmp_path, n, "%s/.%s.XXXXXX", dir, basename(copy));
    free(copy);
    int fd = mkstemp(af->tmp_path);
    if (fd < 0) {
        csf_status st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: cannot create a file in %s: %s",
                                      af->what, af->path, dir, strerror(errno));
        free(dir);
        release(af);
        return st;
    }
    free(dir);
    if (kind == DEST_REPLACE) {
        /* The replacement is the same file to everyone who could read or write the old one. */
        (void)fchmod(fd, old->st_mode & 0777);
        if (fchown(fd, old->st_uid, old->st_gid) != 0) { /* only root may give a file away */ }
    } else {
        mode_t mask = umask(0);
        umask(mask);
        (void)fchmod(fd, 0666 & ~mask); /* mkstemp makes 0600 */
    }
    af->fp = fdopen(fd, "wb");
    if (!af->fp) {
        int e = errno;
        close(fd);
        unlink(af->tmp_path);
        release(af);
        return csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", af->what, af->path, strerror(e));
    }
    return CSF_OK;
}

csf_status csf_atomic_open(csf_atomic_file *af, const char *path, const char *what, csf_error *err)
{
    memset(af, 0, sizeof *af);
    af->what = what;
    if (!path || !*path) return csf_error_set(err, CSF_E_INVALID_ARG, "no path given for the %s", what);
    int alias_fd = descriptor_alias(path);
    dest_kind kind = DEST_THROUGH;
    struct stat old = {0};
    if (alias_fd >= 0) {
        af->path = strdup(path);
    } else {
        csf_status st = classify(path, what, &kind, &af->path, &old, err);
        if (st) return st;
    }
    if (!af->path) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    if (kind == DEST_THROUGH) return open_through(af, path, alias_fd, err);
    return open_temporary(af, kind, &old, err);
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
    /* A terminal, a pipe or /dev/null cannot be synced (EINVAL): that is no failure. */
    if (!e && fsync(fileno(af->fp)) != 0 && !(af->through && (errno == EINVAL || errno == EROFS)))
        e = errno;
    if (fclose(af->fp) != 0 && !e) e = errno;
    af->fp = NULL;
    if (!e && !af->through && rename(af->tmp_path, af->path) != 0) e = errno;
    if (e) {
        if (!af->through) unlink(af->tmp_path);
        csf_status st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", af->what, af->path,
                                      strerror(e));
        release(af);
        return st;
    }
    if (!af->through) sync_folder(af->path);
    release(af);
    return CSF_OK;
}

void csf_atomic_abort(csf_atomic_file *af)
{
    if (af->fp) fclose(af->fp);
    if (af->tmp_path && !af->through) unlink(af->tmp_path);
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
    if (descriptor_alias(path) >= 0) return CSF_OK;
    dest_kind kind;
    char *real = NULL;
    struct stat sb;
    csf_status st = classify(path, what, &kind, &real, &sb, err);
    if (st) return st;
    if (kind == DEST_THROUGH) {
        if (access(real, W_OK) != 0)
            st = csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", what, path, strerror(errno));
        free(real);
        return st;
    }
    /* A new or replaced file needs its folder: the temporary is made there. */
    char *dir = folder_of(real);
    free(real);
    if (!dir) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
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
