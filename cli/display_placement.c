/* The placement screen (cli/display_placement.h). Like ArgyllCMS dispcal's placement window and
 * PsychoPy Monitor Center's patch preview: the meter is put on the screen before the session
 * starts, not during its first readings.
 *
 * Stable means the last four readings lie within 1 % of their mean. A meter resting on or aimed at
 * a steady patch repeats to a few tenths of a percent (the LS-100's stated repeatability is 0.2 %
 * + 1 digit); a meter still being moved, or half off the patch, changes by more, so 1 % tells the
 * two apart without asking more of a colorimeter than it gives. */
#include "cli/display_placement.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "devices/responder.h"

int csf_placement_stable(const double *lum, int n, double *spread_rel)
{
    *spread_rel = NAN;
    if (n < CSF_PLACEMENT_N) return 0;
    double lo = INFINITY, hi = -INFINITY, m = 0;
    for (int i = n - CSF_PLACEMENT_N; i < n; i++) {
        if (!isfinite(lum[i])) return 0;
        lo = fmin(lo, lum[i]);
        hi = fmax(hi, lum[i]);
        m += lum[i];
    }
    m /= CSF_PLACEMENT_N;
    if (!(m > 0)) return 0;
    *spread_rel = (hi - lo) / m;
    return *spread_rel <= CSF_PLACEMENT_SPREAD;
}

static void sleep_s(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&ts, &ts) != 0) {
    }
}

typedef struct {
    double lum[CSF_PLACEMENT_N];
    int n; /* readings so far (the ring holds the last CSF_PLACEMENT_N) */
    int stable;
    double spread;
    char status[200]; /* the reading line, on screen and on the terminal */
    int was_stable;   /* what the terminal last said, when it is not a terminal */
} placement;

/* One reading of the white patch; too dark or over range means the meter is not on the patch
 * yet, any other fault ends the placement. */
static int read_once(placement *pl, csf_photometer *ph, const char *what)
{
    csf_photometer_show_patch(ph, 1, 1, 1);
    csf_photometer_reading r;
    csf_error e;
    csf_error_clear(&e);
    csf_status st = csf_photometer_measure(ph, &r, &e);
    if (st == CSF_E_TOO_DARK || st == CSF_E_SATURATED) {
        pl->n = 0;
        pl->stable = 0;
        snprintf(pl->status, sizeof pl->status, "no reading: %.150s", e.msg);
        return 0;
    }
    if (st) {
        fprintf(stderr, "\ncsfcal: %s: placement: %s\n", what, e.msg);
        return 2;
    }
    double ring[CSF_PLACEMENT_N];
    pl->lum[pl->n % CSF_PLACEMENT_N] = r.lum_cdm2;
    pl->n++;
    int k = pl->n < CSF_PLACEMENT_N ? pl->n : CSF_PLACEMENT_N;
    for (int i = 0; i < k; i++) ring[i] = pl->lum[(pl->n - k + i) % CSF_PLACEMENT_N];
    pl->stable = csf_placement_stable(ring, k, &pl->spread);
    if (isfinite(pl->spread))
        snprintf(pl->status, sizeof pl->status, "reading %.4g cd/m2, last %d within %.2f %%: %s", r.lum_cdm2,
                 CSF_PLACEMENT_N, 100 * pl->spread, pl->stable ? "stable, press Space" : "not stable yet");
    else
        snprintf(pl->status, sizeof pl->status, "reading %.4g cd/m2 (%d of %d for stability)", r.lum_cdm2,
                 pl->n, CSF_PLACEMENT_N);
    return 0;
}

static void terminal_line(placement *pl, int tty)
{
    if (tty) {
        fprintf(stderr, "\rplacement: %-100s", pl->status);
    } else if (pl->n == 1 || pl->stable != pl->was_stable) {
        fprintf(stderr, "placement: %s\n", pl->status);
        pl->was_stable = pl->stable;
    }
    fflush(stderr);
}

/* Space or Escape from the window: 1 Space, -1 Escape or the window closed, 0 nothing. */
static int poll_keys(csf_responder *resp)
{
    csf_response ev;
    int got = 0;
    while (csf_responder_poll(resp, &ev)) {
        if (ev.kind == CSF_RESP_ESCAPE) return -1;
        if (ev.kind == CSF_RESP_PRESS) got = 1;
    }
    return got;
}

int csf_display_placement(csf_presenter *pres, const csf_patch *patch, csf_photometer *ph, const char *what)
{
    csf_error e;
    csf_error_clear(&e);
    csf_responder *resp = NULL;
    if (csf_responder_open("keyboard", csf_presenter_window(pres), &resp, &e)) {
        fprintf(stderr, "csfcal: %s: placement screen: %s\n", what, e.msg);
        return 2;
    }
    csf_patch shown = *patch;
    for (int c = 0; c < 3; c++) {
        shown.drive01[c] = 1;
        shown.bg_drive01[c] = 0.6; /* mid-grey (153 of 255: no dither) so the dark instructions can be read */
    }
    placement pl;
    memset(&pl, 0, sizeof pl);
    snprintf(pl.status, sizeof pl.status, "waiting for the first reading");
    int tty = isatty(2), rc = -1, refused = 0;
    fprintf(stderr,
            "csfcal: %s: placement screen: put the meter on the mark, press Space when the reading is "
            "stable; Escape leaves\n",
            what);
    while (rc < 0) {
        char text[600];
        snprintf(text, sizeof text, "Place the meter on the mark, then press Space. Escape leaves.\n%s%s",
                 pl.status,
                 refused ? "\nSpace: the reading is not stable yet (the meter is moving or off the patch)"
                         : "");
        if (csf_presenter_draw_placement(pres, &shown, text, NULL, &e)) {
            rc = e.code == CSF_E_ABORTED ? 1 : 2;
            if (rc == 2) fprintf(stderr, "csfcal: %s: placement screen: %s\n", what, e.msg);
            break;
        }
        int key = poll_keys(resp);
        if (key < 0) rc = 1;
        else if (key > 0 && pl.stable) rc = 0;
        else if (key > 0) refused = 1;
        if (rc >= 0) break;
        if (read_once(&pl, ph, what)) rc = 2;
        else terminal_line(&pl, tty);
        if (pl.stable) refused = 0;
        sleep_s(0.2); /* a reading takes its own time; this only keeps a fast one from spinning */
    }
    if (tty) fputc('\n', stderr);
    csf_responder_close(resp);
    return rc;
}
