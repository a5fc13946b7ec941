/* Reading a whole outside file into memory, with a size limit, for the parsers of profiles,
 * CSV grids and observer tables. One place decides what a too-large, unreadable or vanished
 * file says to the user. */
#ifndef CSF_FILE_READ_H
#define CSF_FILE_READ_H

#include <stddef.h>

#include "core/csf_status.h"

/* Reads path into a malloc'd buffer with a NUL after the last byte (so text parsers may treat it
 * as a string; *len excludes it). `what` names the file's role in messages ("display profile").
 * Fails with CSF_E_IO (cannot open/read, naming the OS error), CSF_E_FORMAT (larger than
 * max_bytes, naming the limit) or CSF_E_NOMEM. */
csf_status csf_read_file(const char *path, const char *what, size_t max_bytes, char **buf,
                         size_t *len, csf_error *err);

#endif
