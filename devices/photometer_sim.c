/* Simulated photometer: a display model (model/display_model.h) seen through an instrument
 * model. The instrument has relative and absolute noise, a warm-up drift that decays with a time
 * constant, an integration time on a virtual clock, a floor below which it reports "too dark",
 * a saturation level, and injectable faults. Every random draw comes from core/rng.h with the
 * reading number as index, so a resumed session draws what an uninterrupted one would have.
 *
 * Options (sim:key=value,...):
 *   display=crt|lcd|oled|file=PATH.csv|PATH.csv   the simulated monitor (default lcd)
 *   lmax= black= gamma= interaction=              passed to the display model
 *   noise=REL (0.0005)  abs_noise=CDM2 (0.001)   per-reading sd, relative and absolute
 *   warmup_s=S (20)  drift=REL (0.01)            reading scale 1 - drift*exp(-t/warmup_s)
 *   integration_s=S (0.5)                        virtual time per reading
 *   floor_cdm2=L (0.01)  sat_cdm2=L (2000)       measuring range
 *   fault=KIND@N[+COUNT]                         from reading number N (0-based). timeout and
 *                                                garbage hit reading N only; the others persist,
 *                                                or last COUNT readings (N to N+COUNT-1) when given
 *                                                (a sensor that slips off the screen and back).
 * Fault kinds: what the instrument says itself: unplug (gone), timeout (silent), garbage
 * (unreadable answer), dark (too dark: fell off the screen facing the desk, or cap on), saturate
 * (over range). What it does not say (calib/meter_check.h catches them): stuck (repeats its last
 * answer), offscreen (reads the room's light, the same for every patch), dim (the display dims
 * itself by 10 %), negative, nan, huge (x 1e5) luminance, badxyz (XYZ's Y 30 % off the
 * luminance), glare (the sensor sees a lamp: white's light x 1.5 whatever the patch). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/display_model.h"
#include "devices/photometer_driver.h"
#include "core/rng.h"
#include "core/spec.h"

enum {
    FAULT_NONE, FAULT_UNPLUG, FAULT_TIMEOUT, FAULT_GARBAGE, FAULT_DARK, FAULT_SATURATE,
    FAULT_STUCK, FAULT_OFFSCREEN, FAULT_DIM, FAULT_NEGATIVE, FAULT_NAN, FAULT_HUGE, FAULT_BADXYZ,
    FAULT_GLARE, FAULT_COUNT
};
static const char *fault_names[] = {"none", "unplug", "timeout", "garbage", "dark", "saturate", "stuck",
                                    "offscreen", "dim", "negative", "nan", "huge", "badxyz", "glare"};
/* what the sensor sees off the screen (a lit room, a wall): the same for every patch */
static const double AMBIENT_XYZ[3] = {0.48, 0.5, 0.52};

/* rng streams: what is being drawn */
enum { STREAM_REL = 0x5e01, STREAM_ABS, STREAM_X, STREAM_Z };

typedef struct {
    csf_display_model *display;
    char display_spec[1100];
    uint64_t seed;
    double noise_rel, noise_abs_cdm2, warmup_s, drift, integration_s, floor_cdm2, sat_cdm2;
    int fault;
    uint64_t fault_at;
    uint64_t fault_count; /* 0: the kind's default (one reading, or for good) */
    uint64_t n;   /* readings attempted so far: the rng index of the next one */
    csf_photometer_reading last; /* the last answer given (what a stuck meter repeats) */
    int have_last;
    double t_s;   /* virtual clock */
} sim_state;

static int num(const char *v, double lo, double hi, double *out)
{
    return csf_number_parse(v, lo, hi, out) == CSF_NUM_OK ? 0 : -1;
}

static void sim_defaults(sim_state *s, uint64_t seed)
{
    s->seed = seed;
    s->noise_rel = 0.0005;
    s->noise_abs_cdm2 = 0.001;
    s->warmup_s = 20;
    s->drift = 0.01;
    s->integration_s = 0.5;
    s->floor_cdm2 = 0.01;
    s->sat_cdm2 = 2000;
}

/* fault=KIND@N or KIND@N+COUNT */
static csf_status parse_fault(sim_state *s, const char *v, csf_error *err)
{
    const char *at = strchr(v, '@');
    size_t kl = at ? (size_t)(at - v) : strlen(v);
    s->fault = -1;
    for (int f = 1; f < FAULT_COUNT; f++)
        if (strlen(fault_names[f]) == kl && strncmp(v, fault_names[f], kl) == 0) s->fault = f;
    char nbuf[64] = "";
    const char *plus = at ? strchr(at + 1, '+') : NULL;
    double x = 0, cnt = 0;
    if (at) snprintf(nbuf, sizeof nbuf, "%.*s", plus ? (int)(plus - at - 1) : (int)strlen(at + 1), at + 1);
    if (s->fault < 0 || !at || num(nbuf, 0, 1e9, &x) || x != floor(x) ||
        (plus && (num(plus + 1, 1, 1e9, &cnt) || cnt != floor(cnt))))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "sim photometer: fault=%s not understood (KIND@N or KIND@N+COUNT, KIND one of "
                             "unplug, timeout, garbage, dark, saturate, stuck, offscreen, dim, negative, "
                             "nan, huge, badxyz, glare; N a reading number >= 0, COUNT "
                             "the readings it lasts, >= 1)",
                             v);
    s->fault_at = (uint64_t)x;
    s->fault_count = (uint64_t)cnt;
    return CSF_OK;
}

/* The instrument's numeric keys: name, range, what the range is in, and the field it sets. */
typedef struct {
    const char *key;
    double lo, hi;
    const char *what;
    size_t off;
} sim_key;
#define SK(k, lo, hi, what, field)                                                                           \
    {                                                                                                        \
        k, lo, hi, what, offsetof(sim_state, field)                                                          \
    }
static const sim_key sim_keys[] = {
    SK("noise", 0, 0.2, "relative sd", noise_rel),
    SK("abs_noise", 0, 10, "cd/m2", noise_abs_cdm2),
    SK("warmup_s", 0.001, 3600, "seconds", warmup_s),
    SK("drift", 0, 0.5, "relative", drift),
    SK("integration_s", 0.001, 60, "seconds", integration_s),
    SK("floor_cdm2", 0, 100, "cd/m2", floor_cdm2),
    SK("sat_cdm2", 1, 1e6, "cd/m2", sat_cdm2),
};

/* One key=value: the simulated display's keys gather in kind and extra (the display model
 * judges them), the instrument's set s. */
static csf_status sim_option(sim_state *s, const char *k, const char *v, char kind[512], char extra[512],
                             csf_error *err)
{
    if (!v) return csf_error_set(err, CSF_E_INVALID_ARG, "sim photometer option '%s' is not key=value", k);
    if (strcmp(k, "display") == 0) {
        snprintf(kind, 512, "%s", v);
    } else if (strcmp(k, "file") == 0) {
        snprintf(kind, 512, "file=%s", v);
    } else if (!strcmp(k, "lmax") || !strcmp(k, "black") || !strcmp(k, "gamma") ||
               !strcmp(k, "interaction")) {
        size_t l = strlen(extra);
        snprintf(extra + l, 512 - l, ",%s=%s", k, v);
    } else if (strcmp(k, "fault") == 0) {
        return parse_fault(s, v, err);
    } else {
        for (size_t i = 0; i < sizeof sim_keys / sizeof sim_keys[0]; i++) {
            const sim_key *sk = &sim_keys[i];
            if (strcmp(k, sk->key) != 0) continue;
            double x;
            if (num(v, sk->lo, sk->hi, &x))
                return csf_error_set(err, CSF_E_INVALID_ARG,
                                     "sim photometer: %s=%s out of range (%s %g to %g)", k, v, sk->what,
                                     sk->lo, sk->hi);
            *(double *)((char *)s + sk->off) = x;
            return CSF_OK;
        }
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "sim photometer: unknown option '%s' (known: display, lmax, black, gamma, "
                             "interaction, noise, abs_noise, warmup_s, drift, integration_s, floor_cdm2, "
                             "sat_cdm2, fault)",
                             k);
    }
    return CSF_OK;
}

static csf_status sim_open(const char *options, uint64_t seed, void **state, csf_error *err)
{
    if (strlen(options) >= 1024)
        return csf_error_set(err, CSF_E_INVALID_ARG, "sim photometer options longer than %d characters",
                             1023);
    sim_state *s = calloc(1, sizeof *s);
    csf_spec *items = malloc(sizeof *items);
    if (!s || !items) {
        free(s);
        free(items);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    sim_defaults(s, seed);
    char kind[512] = "lcd", extra[512] = "";
    csf_status st = csf_spec_split(options, "sim photometer", items, err);
    for (int i = 0; st == CSF_OK && i < items->n; i++)
        st = sim_option(s, items->item[i].key, items->item[i].value, kind, extra, err);
    free(items);
    if (!st) {
        snprintf(s->display_spec, sizeof s->display_spec, "%s%s", kind, extra);
        st = csf_display_model_create(s->display_spec, &s->display, err);
    }
    if (st) {
        free(s);
        return st;
    }
    *state = s;
    return CSF_OK;
}

static void sim_close(void *state)
{
    sim_state *s = state;
    if (!s) return;
    csf_display_model_free(s->display);
    free(s);
}

static csf_status sim_identify(void *state, char *buf, size_t len, csf_error *err)
{
    sim_state *s = state;
    (void)err;
    snprintf(buf, len, "csfcal simulated photometer (display=%s, noise=%g, abs_noise=%g cd/m2, "
             "integration %g s)", s->display_spec, s->noise_rel, s->noise_abs_cdm2, s->integration_s);
    return CSF_OK;
}

static void sim_resume_at(void *state, uint64_t reading_index, double t_s)
{
    sim_state *s = state;
    s->n = reading_index;
    if (t_s > s->t_s) s->t_s = t_s;
}

static void sim_wait(void *state, double seconds)
{
    sim_state *s = state;
    s->t_s += seconds;
}

/* True light under the sensor: from the uniform patch, or averaged over framebuffer pixels. */
static csf_status sensed_light(sim_state *s, const csf_screen_source *src, double xyz[3], csf_error *err)
{
    if (src && src->pixels) {
        const void *px;
        size_t n_px = 0;
        int bits = 8;
        csf_status st = src->pixels(src->user, &px, &n_px, &bits);
        if (st) return csf_error_set(err, st, "screen source failed to give the pixels under the sensor");
        if (n_px == 0 || bits < 1 || bits > 16)
            return csf_error_set(err, CSF_E_INVALID_ARG, "screen source gave %zu pixels of %d bits "
                                 "(need >= 1 pixel, 1 to 16 bits)", n_px, bits);
        double maxv = (double)((1u << bits) - 1);
        double acc[3] = {0, 0, 0};
        for (size_t i = 0; i < n_px; i++) {
            double v[3], x[3];
            for (int c = 0; c < 3; c++)
                v[c] = bits <= 8 ? ((const unsigned char *)px)[3 * i + c] / maxv
                                 : ((const uint16_t *)px)[3 * i + c] / maxv;
            csf_display_model_xyz(s->display, v[0], v[1], v[2], x);
            for (int k = 0; k < 3; k++) acc[k] += x[k];
        }
        for (int k = 0; k < 3; k++) xyz[k] = acc[k] / (double)n_px;
        return CSF_OK;
    }
    if (src && src->patch) {
        double rgb[3];
        csf_status st = src->patch(src->user, rgb);
        if (st) return csf_error_set(err, st, "screen source failed to give the patch under the sensor");
        csf_display_model_xyz(s->display, rgb[0], rgb[1], rgb[2], xyz);
        return CSF_OK;
    }
    return csf_error_set(err, CSF_E_INVALID_ARG, "simulated photometer has no screen source");
}

static csf_status sim_measure(void *state, const csf_screen_source *src, csf_photometer_reading *out,
                              csf_error *err)
{
    sim_state *s = state;
    uint64_t i = s->n++;
    s->t_s += s->integration_s;
    out->t_s = s->t_s;
    out->integration_s = s->integration_s;
    int faulty = s->fault && i >= s->fault_at && (s->fault_count == 0 || i - s->fault_at < s->fault_count);
    if (faulty) {
        switch (s->fault) {
        case FAULT_UNPLUG:
            return csf_error_set(err, CSF_E_GONE, "photometer disconnected at reading %llu "
                                 "(reconnect it and resume the session)", (unsigned long long)i);
        case FAULT_TIMEOUT:
            if (i == s->fault_at || s->fault_count)
                return csf_error_set(err, CSF_E_TIMEOUT, "photometer did not answer reading %llu within "
                                     "%.1f s", (unsigned long long)i, 10 * s->integration_s + 2);
            break;
        case FAULT_GARBAGE:
            if (i == s->fault_at || s->fault_count)
                return csf_error_set(err, CSF_E_PROTOCOL, "photometer sent an unreadable answer to "
                                     "reading %llu (bytes 0x%02x 0x%02x ...)", (unsigned long long)i,
                                     (unsigned)(csf_rng_u64(s->seed, 7, i) & 0xff),
                                     (unsigned)((csf_rng_u64(s->seed, 7, i) >> 8) & 0xff));
            break;
        default:
            break;
        }
    }
    double xyz[3];
    csf_status st = sensed_light(s, src, xyz, err);
    if (st) return st;
    if (faulty && s->fault == FAULT_SATURATE) {
        /* e.g. the sensor slipped onto a brighter light source */
        for (int k = 0; k < 3; k++) xyz[k] = s->sat_cdm2 * 2;
    }
    if (faulty && s->fault == FAULT_DARK) {
        /* e.g. the sensor fell off the screen, facing the desk */
        for (int k = 0; k < 3; k++) xyz[k] = 0;
    }
    if (faulty && s->fault == FAULT_STUCK && s->have_last) {
        double t = out->t_s;
        *out = s->last;
        out->t_s = t;
        return CSF_OK;
    }
    if (faulty && s->fault == FAULT_OFFSCREEN) memcpy(xyz, AMBIENT_XYZ, sizeof xyz);
    if (faulty && s->fault == FAULT_GLARE) {
        csf_display_model_xyz(s->display, 1, 1, 1, xyz);
        for (int k = 0; k < 3; k++) xyz[k] *= 1.5;
    }
    if (faulty && s->fault == FAULT_DIM)
        for (int k = 0; k < 3; k++) xyz[k] *= 0.9;
    if (xyz[1] > s->sat_cdm2)
        return csf_error_set(err, CSF_E_SATURATED, "photometer saturated at reading %llu (above its "
                             "%g cd/m2 range)", (unsigned long long)i, s->sat_cdm2);
    double drift = 1.0 - s->drift * exp(-s->t_s / s->warmup_s);
    double rel = 1.0 + s->noise_rel * csf_rng_normal(s->seed, STREAM_REL, i);
    double absn = s->noise_abs_cdm2 * csf_rng_normal(s->seed, STREAM_ABS, i);
    double Y = xyz[1] * drift * rel + absn;
    if (Y < s->floor_cdm2)
        return csf_error_set(err, CSF_E_TOO_DARK, "too dark for the photometer at reading %llu "
                             "(below its %g cd/m2 floor)", (unsigned long long)i, s->floor_cdm2);
    double scale = xyz[1] > 0 ? Y / xyz[1] : 1.0;
    out->lum_cdm2 = Y;
    out->xyz[0] = xyz[0] * scale * (1.0 + 0.5 * s->noise_rel * csf_rng_normal(s->seed, STREAM_X, i));
    out->xyz[1] = Y;
    out->xyz[2] = xyz[2] * scale * (1.0 + 0.5 * s->noise_rel * csf_rng_normal(s->seed, STREAM_Z, i));
    out->has_xyz = 1;
    if (faulty) {
        /* answers that parse but cannot be light (a firmware or range-conversion fault) */
        if (s->fault == FAULT_NEGATIVE) out->lum_cdm2 = out->xyz[1] = -Y;
        if (s->fault == FAULT_NAN) out->lum_cdm2 = NAN;
        if (s->fault == FAULT_HUGE) out->lum_cdm2 = out->xyz[1] = Y * 1e5;
        if (s->fault == FAULT_BADXYZ) out->xyz[1] = Y * 1.3;
    }
    s->last = *out;
    s->have_last = 1;
    return CSF_OK;
}

static double sim_integration_s(void *state)
{
    return ((const sim_state *)state)->integration_s;
}

const csf_photometer_driver csf_photometer_sim_driver = {
    .name = "sim",
    .description = "simulated photometer and display (noise, drift, range, faults)",
    .caps = CSF_PHOT_CAP_XYZ | CSF_PHOT_CAP_SIMULATED,
    .open = sim_open,
    .identify = sim_identify,
    .measure = sim_measure,
    .resume_at = sim_resume_at,
    .wait = sim_wait,
    .close = sim_close,
    .integration_s = sim_integration_s,
    /* a spot meter like the LS-100 (1 deg), so a simulated session checks its patch as the lab's
     * most common meter would */
    .field_deg = 1.0,
};
