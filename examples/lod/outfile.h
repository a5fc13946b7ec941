/* Output files that appear whole or not at all: written to PATH.tmp.XXXXXX beside the
 * destination, flushed, fsynced and renamed over it; on any failure the temporary is removed, the
 * previous file stays, and the message names the file and the OS error. */
#ifndef LOD_OUTFILE_H
#define LOD_OUTFILE_H

#include <stddef.h>
#include <stdio.h>

typedef struct {
    FILE *f;
    char *path, *tmp;
} lod_outfile;

/* 0, or -1 with the message in err. */
int lod_outfile_open(lod_outfile *o, const char *path, char *err, size_t err_len);
/* Finishes the file (ok = 1) or throws it away (ok = 0). 0 when the file is in place. */
int lod_outfile_close(lod_outfile *o, int ok, char *err, size_t err_len);

#endif
