/* Trial pieces shared by observer calibration (calib/observer_calib.c) and user studies
 * (studies/study_run.c): storing a trial with its frame timing, waiting for a person's answer
 * through the responders, blank and text screens with pause handling, and the rounding that
 * makes a resumed simulated run reproduce an uninterrupted one. One copy, two callers. */
#ifndef CSF_TRIAL_IO_H
#define CSF_TRIAL_IO_H

#include <signal.h>

#include "devices/responder.h"
#include "results/store/store.h"
#include "stimuli/presenter.h"

/* Values that reach the store are rounded to 9 significant digits: far below what a float GPU
 * pipeline can show, and a resumed run (whose virtual clock restarted at zero, so times differ in
 * the last bits) then reproduces an uninterrupted one exactly. */
double csf_round9(double v);

/* Where a person's answers come from while trials run. stop points at the session's
 * SIGINT/SIGTERM flag (may be NULL); paused is set by Escape or a signal. */
typedef struct {
    csf_presenter *pres;
    csf_responder *resp;       /* NULL for a simulated person */
    volatile sig_atomic_t *stop;
    int paused;
} csf_trial_io;

/* Commits a trial and its frame intervals (rec, when have_rec) in one transaction, then frees
 * the record: a crash cannot leave a trial without its timing. */
csf_status csf_trial_io_store(csf_store *store, const csf_trial *t, csf_trial_record *rec,
                              int have_rec, csf_error *err);

/* Blank (mean grey) frames for seconds, with the fixation mark when fixation is set; Escape
 * pauses (io->paused) and ends them early. */
csf_status csf_trial_io_blank(csf_trial_io *io, double seconds, int fixation, csf_error *err);

/* A two-way answer from a person: an interval key (choice 0 first/left/"same"/"no", 1 second/
 * right/"different"/"yes") or the left/right mouse button. Answers made before t0 (the end of
 * the last interval, on csf_responder_now's clock) are ignored, so reaction times are never
 * negative. window_s > 0: no answer within it gives *choice = -1 (a missed response). */
csf_status csf_trial_io_wait_choice(csf_trial_io *io, double t0, double window_s, int *choice,
                                    double *rt_s, csf_error *err);

/* Text screen; a person reads it and presses any key (Escape = pause). Not shown to a simulated
 * person (io->resp NULL). */
csf_status csf_trial_io_screen(csf_trial_io *io, const char *text, csf_error *err);

#endif
