/* Screen mirror writer (see devices/screen_mirror.h for the contract and the file format). */
#include "devices/screen_mirror.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/file_write.h"

struct csf_screen_mirror {
    char *path;
};

csf_status csf_screen_mirror_from_env(csf_screen_mirror **out, csf_error *err)
{
    *out = NULL;
    const char *path = getenv(CSF_SCREEN_MIRROR_ENV);
    if (!path || !*path) return CSF_OK;
    csf_status st = csf_check_output_path(path, "screen mirror (" CSF_SCREEN_MIRROR_ENV ")", err);
    if (st) return st;
    csf_screen_mirror *m = calloc(1, sizeof *m);
    if (!m || !(m->path = strdup(path))) {
        free(m);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    *out = m;
    return CSF_OK;
}

csf_status csf_screen_mirror_write(csf_screen_mirror *m, uint64_t seq, const double rgb01[3], size_t n_px,
                                   csf_error *err)
{
    double v[3];
    for (int c = 0; c < 3; c++) v[c] = !(rgb01[c] > 0) ? 0 : rgb01[c] > 1 ? 1 : rgb01[c];
    char buf[256];
    int n = snprintf(buf, sizeof buf, "csfcal-screen-mirror 1\nseq %llu\ndrive %.17g %.17g %.17g\npixels %zu\n",
                     (unsigned long long)seq, v[0], v[1], v[2], n_px);
    return csf_write_file_atomic(m->path, "screen mirror", buf, (size_t)n, err);
}

const char *csf_screen_mirror_path(const csf_screen_mirror *m) { return m->path; }

void csf_screen_mirror_free(csf_screen_mirror *m)
{
    if (!m) return;
    free(m->path);
    free(m);
}
