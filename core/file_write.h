/* Writing an output file so that a reader never sees half of it: the bytes go to a temporary file
 * in the same folder, are flushed to the disk, and only then renamed over the destination. On any
 * failure (a full disk, a read-only folder, a vanished folder) the temporary is removed, the
 * destination is left as it was, and the message carries the OS error ("No space left on device").
 * Every writer of a user-visible file (exports, plots, reports, tables) goes through here.
 *
 * What is at the destination decides how it is written, as a shell redirection would:
 * - nothing: a new file with the permissions the umask allows;
 * - a regular file: replaced atomically; the replacement keeps its mode (and, for root, owner);
 * - a symbolic link: followed; the file it points to is replaced and the link stays a link; a
 *   link to nothing is refused (csfcal does not create files where a planted link says);
 * - a character device or a FIFO (/dev/null, a terminal, a pipe): written in place, never
 *   replaced; "-", /dev/stdout, /dev/stderr, /dev/fd/N and /proc/self/fd/N write through this
 *   process's own descriptor, so an appending shell redirection stays appending;
 * - a folder, a block device or a socket: refused. */
#ifndef CSF_FILE_WRITE_H
#define CSF_FILE_WRITE_H

#include <stddef.h>
#include <stdio.h>

#include "core/csf_status.h"

typedef struct {
    FILE *fp;       /* write the contents here */
    char *path;     /* the destination */
    char *tmp_path; /* the temporary beside it; renamed to path by commit */
    const char *what;
    int through;    /* written in place (device, FIFO, descriptor): no temporary, no rename */
} csf_atomic_file;

/* Creates the temporary beside `path`. `what` names the file's role in messages ("ICC profile").
 * Fails with CSF_E_IO naming the folder and the OS error, or CSF_E_NOMEM. */
csf_status csf_atomic_open(csf_atomic_file *af, const char *path, const char *what, csf_error *err);
/* Flushes, fsyncs and renames the temporary over the destination, then fsyncs the folder. On
 * failure removes the temporary and reports the OS error. Always releases af. */
csf_status csf_atomic_commit(csf_atomic_file *af, csf_error *err);
/* Drops the temporary; the destination is untouched. Safe on a zeroed or already released af. */
void csf_atomic_abort(csf_atomic_file *af);

/* The whole of buf as the contents of path, atomically. */
csf_status csf_write_file_atomic(const char *path, const char *what, const void *buf, size_t len,
                                 csf_error *err);

/* Checks before any work is done that `path` can be written, by the rules above: a file's folder
 * exists and is writable, a device or FIFO is writable, and nothing refused is there. Creates
 * nothing. */
csf_status csf_check_output_path(const char *path, const char *what, csf_error *err);

#endif
