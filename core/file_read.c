#include "core/file_read.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

csf_status csf_read_file(const char *path, const char *what, size_t max_bytes, char **buf,
                         size_t *len, csf_error *err)
{
    *buf = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return csf_error_set(err, CSF_E_IO, "cannot open %s %s: %s", what, path, strerror(errno));
    /* Grow as we read rather than trusting the size up front: the path may be a pipe or a file
     * still being written. */
    size_t cap = 65536, n = 0;
    char *data = malloc(cap + 1);
    csf_status st = CSF_OK;
    while (data) {
        if (n == cap) {
            if (cap > max_bytes) break;
            char *grown = realloc(data, cap * 2 + 1);
            if (!grown) break;
            data = grown;
            cap *= 2;
        }
        size_t got = fread(data + n, 1, cap - n, f);
        n += got;
        if (got == 0) break;
    }
    if (!data || (n == cap && !feof(f) && cap <= max_bytes))
        st = csf_error_set(err, CSF_E_NOMEM, "out of memory reading %s %s", what, path);
    else if (ferror(f))
        st = csf_error_set(err, CSF_E_IO, "cannot read %s %s: %s", what, path, strerror(errno));
    else if (n > max_bytes)
        st = csf_error_set(err, CSF_E_FORMAT, "%s %s is larger than the limit of %zu bytes", what, path,
                           max_bytes);
    fclose(f);
    if (st != CSF_OK) {
        free(data);
        return st;
    }
    data[n] = '\0';
    *buf = data;
    *len = n;
    return CSF_OK;
}
