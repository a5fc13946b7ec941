/* Screen mirror reader and the emulators' light model (see emu_screen.h). */
#include "tests/emu/emu_screen.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/screen_mirror.h"
#include "core/rng.h"

int emu_screen_parse(const char *text, size_t len, emu_screen_patch *out, char *why, size_t why_len)
{
    char buf[1024];
    if (len >= sizeof buf) {
        snprintf(why, why_len, "screen mirror longer than %zu bytes", sizeof buf - 1);
        return -1;
    }
    memcpy(buf, text, len);
    buf[len] = 0;
    memset(out, 0, sizeof *out);
    int have_magic = 0, have_drive = 0, have_seq = 0;
    out->n_px = 1;
    char *save = NULL;
    for (char *line = strtok_r(buf, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        unsigned long long u;
        double r, g, b;
        char tail;
        if (!have_magic) {
            if (sscanf(line, "csfcal-screen-mirror %llu %c", &u, &tail) != 1 || u != 1) {
                snprintf(why, why_len, "not a version-1 screen mirror (first line '%.40s')", line);
                return -1;
            }
            have_magic = 1;
        } else if (strncmp(line, "seq ", 4) == 0) {
            if (sscanf(line + 4, "%llu %c", &u, &tail) != 1) break;
            out->seq = u;
            have_seq = 1;
        } else if (strncmp(line, "drive ", 6) == 0) {
            if (sscanf(line + 6, "%lf %lf %lf %c", &r, &g, &b, &tail) != 3) break;
            double v[3] = {r, g, b};
            for (int c = 0; c < 3; c++) {
                if (!(v[c] >= 0 && v[c] <= 1)) {
                    snprintf(why, why_len, "screen mirror drive value %g outside 0..1", v[c]);
                    return -1;
                }
                out->drive[c] = v[c];
            }
            have_drive = 1;
        } else if (strncmp(line, "pixels ", 7) == 0) {
            if (sscanf(line + 7, "%llu %c", &u, &tail) != 1 || u == 0) break;
            out->n_px = (size_t)u;
        } /* other lines: a later version's; ignored */
    }
    if (!have_magic || !have_seq || !have_drive) {
        snprintf(why, why_len, "screen mirror incomplete or malformed (needs the magic line, seq and drive)");
        return -1;
    }
    return 0;
}

int emu_screen_read(const char *path, emu_screen_patch *out, char *why, size_t why_len)
{
    if (!path) path = getenv(CSF_SCREEN_MIRROR_ENV);
    if (!path || !*path) {
        snprintf(why, why_len, "no screen mirror: set %s", CSF_SCREEN_MIRROR_ENV);
        return -1;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, why_len, "screen mirror %s: %s", path, strerror(errno));
        return -1;
    }
    char buf[1024];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    return emu_screen_parse(buf, n, out, why, why_len);
}

int emu_light_open(emu_light *l, const char *display_spec, char *why, size_t why_len)
{
    memset(l, 0, sizeof *l);
    l->gain = 1;
    csf_error e;
    if (csf_display_model_create(display_spec, &l->display, &e)) {
        snprintf(why, why_len, "%s", e.msg);
        return -1;
    }
    return 0;
}

void emu_light_close(emu_light *l)
{
    csf_display_model_free(l->display);
    l->display = NULL;
}

int emu_light_measure(emu_light *l, double xyz[3], char *why, size_t why_len)
{
    emu_screen_patch p;
    if (emu_screen_read(NULL, &p, why, why_len)) return -1;
    csf_display_model_xyz(l->display, p.drive[0], p.drive[1], p.drive[2], xyz);
    uint64_t i = l->n++;
    double rel = 1 + l->noise_rel * csf_rng_normal(l->seed, 0xe301, i);
    double absn = l->noise_abs * csf_rng_normal(l->seed, 0xe302, i);
    double Y = xyz[1] * l->gain * rel + absn;
    double s = xyz[1] > 0 ? Y / xyz[1] : 1;
    for (int k = 0; k < 3; k++) xyz[k] *= s;
    xyz[1] = Y;
    return 0;
}
