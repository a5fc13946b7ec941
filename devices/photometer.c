/* Photometer registry and the thin layer every instrument shares: open by spec, keep the screen
 * source, forward calls to the driver's function pointers. */
#include "devices/photometer.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "devices/photometer_driver.h"
#include "devices/screen_mirror.h"

struct csf_photometer {
    const csf_photometer_driver *drv;
    void *state;
    csf_screen_source src;
    int own_source;         /* 1: the built-in uniform patch is the source */
    double patch_rgb01[3];
    char spec[512];
    csf_screen_mirror *mirror; /* CSFCAL_SCREEN_MIRROR: tells an emulator what is on screen */
    uint64_t n_asked;          /* readings asked for (the mirror's seq) */
};

static const csf_photometer_driver *const drivers[] = {
    &csf_photometer_sim_driver,
    &csf_photometer_colorcal2_driver,
    &csf_photometer_colorhug2_driver,
    &csf_photometer_ls100_driver, &csf_photometer_ls110_driver, &csf_photometer_cs100a_driver,
    &csf_photometer_pr655_driver, &csf_photometer_pr670_driver, &csf_photometer_spotread_driver,
    NULL,
};

const csf_photometer_driver *const *csf_photometer_drivers(void)
{
    return drivers;
}

static csf_status patch_source(void *user, double rgb01[3])
{
    const csf_photometer *p = user;
    memcpy(rgb01, p->patch_rgb01, sizeof p->patch_rgb01);
    return CSF_OK;
}

csf_status csf_photometer_open(const char *spec, uint64_t seed, csf_photometer **out, csf_error *err)
{
    *out = NULL;
    if (!spec || !*spec)
        return csf_error_set(err, CSF_E_INVALID_ARG, "no photometer given (e.g. --photometer sim:display=lcd)");
    if (strlen(spec) >= sizeof((csf_photometer *)0)->spec)
        return csf_error_set(err, CSF_E_INVALID_ARG, "photometer spec longer than %zu characters",
                             sizeof((csf_photometer *)0)->spec - 1);
    const char *colon = strchr(spec, ':');
    size_t nlen = colon ? (size_t)(colon - spec) : strlen(spec);
    const csf_photometer_driver *drv = NULL;
    for (int i = 0; drivers[i]; i++)
        if (strlen(drivers[i]->name) == nlen && strncmp(drivers[i]->name, spec, nlen) == 0) drv = drivers[i];
    if (!drv) {
        char known[256] = "";
        for (int i = 0; drivers[i]; i++) {
            if (i) strncat(known, ", ", sizeof known - strlen(known) - 1);
            strncat(known, drivers[i]->name, sizeof known - strlen(known) - 1);
        }
        return csf_error_set(err, CSF_E_NOT_FOUND,
                             "unknown photometer '%.*s' (known in this build: %s)", (int)nlen, spec, known);
    }
    csf_photometer *p = calloc(1, sizeof *p);
    if (!p) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    p->drv = drv;
    snprintf(p->spec, sizeof p->spec, "%s", spec);
    csf_status st = CSF_OK;
    if (!(drv->caps & CSF_PHOT_CAP_SIMULATED)) st = csf_screen_mirror_from_env(&p->mirror, err);
    if (!st) st = drv->open(colon ? colon + 1 : "", seed, &p->state, err);
    if (st) {
        csf_screen_mirror_free(p->mirror);
        free(p);
        return st;
    }
    csf_photometer_set_source(p, NULL);
    *out = p;
    return CSF_OK;
}

void csf_photometer_close(csf_photometer *p)
{
    if (!p) return;
    p->drv->close(p->state);
    csf_screen_mirror_free(p->mirror);
    free(p);
}

csf_status csf_photometer_identify(csf_photometer *p, char *buf, size_t len, csf_error *err)
{
    return p->drv->identify(p->state, buf, len, err);
}

/* What the screen source shows, as drive values: the uniform patch, or the mean framebuffer level
 * of the rendered pixels per channel. */
static csf_status source_drive(csf_photometer *p, double rgb01[3], size_t *n_px, csf_error *err)
{
    *n_px = 1;
    if (p->src.patch) {
        csf_status st = p->src.patch(p->src.user, rgb01);
        return st ? csf_error_set(err, st, "screen source failed to give the patch for the screen mirror") : CSF_OK;
    }
    const void *px = NULL;
    int bits = 8;
    csf_status st = p->src.pixels(p->src.user, &px, n_px, &bits);
    if (st) return csf_error_set(err, st, "screen source failed to give the pixels for the screen mirror");
    if (*n_px == 0 || bits < 1 || bits > 16)
        return csf_error_set(err, CSF_E_INVALID_ARG, "screen source gave %zu pixels of %d bits", *n_px, bits);
    double acc[3] = {0, 0, 0}, maxv = (double)((1u << bits) - 1);
    for (size_t i = 0; i < *n_px; i++)
        for (int c = 0; c < 3; c++)
            acc[c] += bits <= 8 ? ((const unsigned char *)px)[3 * i + c] : ((const uint16_t *)px)[3 * i + c];
    for (int c = 0; c < 3; c++) rgb01[c] = acc[c] / ((double)*n_px * maxv);
    return CSF_OK;
}

csf_status csf_photometer_measure(csf_photometer *p, csf_photometer_reading *out, csf_error *err)
{
    memset(out, 0, sizeof *out);
    if (p->mirror) {
        double rgb[3];
        size_t n_px;
        csf_status st = source_drive(p, rgb, &n_px, err);
        if (!st) st = csf_screen_mirror_write(p->mirror, p->n_asked, rgb, n_px, err);
        if (st) return st;
    }
    p->n_asked++;
    return p->drv->measure(p->state, &p->src, out, err);
}

void csf_photometer_set_source(csf_photometer *p, const csf_screen_source *src)
{
    if (src) {
        p->src = *src;
        p->own_source = 0;
    } else {
        p->src.patch = patch_source;
        p->src.pixels = NULL;
        p->src.user = p;
        p->own_source = 1;
    }
}

void csf_photometer_show_patch(csf_photometer *p, double r01, double g01, double b01)
{
    p->patch_rgb01[0] = r01;
    p->patch_rgb01[1] = g01;
    p->patch_rgb01[2] = b01;
    if (!p->own_source) csf_photometer_set_source(p, NULL);
}

void csf_photometer_resume_at(csf_photometer *p, uint64_t reading_index, double t_s)
{
    if (p->drv->resume_at) p->drv->resume_at(p->state, reading_index, t_s);
}

void csf_photometer_wait(csf_photometer *p, double seconds)
{
    if (!(seconds > 0)) return;
    if (p->drv->wait) {
        p->drv->wait(p->state, seconds);
        return;
    }
    struct timespec ts = {(time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9)};
    while (nanosleep(&ts, &ts) != 0) {
    }
}

int csf_photometer_caps(const csf_photometer *p)
{
    return p->drv->instance_caps ? p->drv->instance_caps(p->state) : p->drv->caps;
}
double csf_photometer_integration_s(const csf_photometer *p)
{
    return p->drv->integration_s ? p->drv->integration_s(p->state) : 0.0;
}
const char *csf_photometer_driver_name(const csf_photometer *p) { return p->drv->name; }
const char *csf_photometer_spec(const csf_photometer *p) { return p->spec; }
void csf_photometer_field(const csf_photometer *p, double *field_deg, double *field_mm)
{
    *field_deg = p->drv->field_deg;
    *field_mm = p->drv->field_mm;
    if (p->drv->instance_field) p->drv->instance_field(p->state, field_deg, field_mm);
}
