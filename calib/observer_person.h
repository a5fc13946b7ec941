/* The person of an observer session behind the same few calls, simulated (model/observer_sim)
 * or human (a responder on the presenter's window): fade-trial frames, the click that says where a
 * grating was, text screens and the pause offer. Internal to the observer procedure. */
#ifndef CSF_OBSERVER_PERSON_H
#define CSF_OBSERVER_PERSON_H

#include <signal.h>

#include "calib/observer_screen.h"
#include "devices/responder.h"
#include "model/observer_sim.h"
#include "stimuli/geometry.h"
#include "stimuli/presenter.h"

/* Set by SIGINT/SIGTERM during a session: the person pauses as Escape would. */
extern volatile sig_atomic_t obs_stop_requested;

typedef struct {
    csf_observer_sim *sim;
    csf_obs_screen *eyes; /* view=frame: contrasts are measured from the frames */
    void (*seen_hook)(void *ctx, int n, const double *seen, const double *reported);
    void *seen_hook_ctx;
    csf_responder *resp;
    csf_presenter *pres;
    const csf_geometry *geom;
    /* fade trial in progress */
    csf_sim_fade_trial tr;
    int pressed, paused;
    double onset_s, press_rel_s, contrast_at_press;
    int first_frame;
    double period_s;
    int catch_trial;
    double sim_rt_total_s; /* simulated answers' and reading times, which no frame clock counts */
} person;

/* The seconds a person takes to read a text screen: its words at 238 a minute, the mean silent
 * reading rate of adults for non-fiction (Brysbaert 2019). A simulated person spends that on every
 * screen, as a real one does on the session's clock. */
double obs_reading_s(const char *text);
/* Called for every frame of a fade trial (presenter callback or our own blank frames). */
int obs_person_fade_frame(person *p, double t_s, double contrast_shown);
int obs_fade_stop_cb(void *ctx, const csf_frame_info *f);
/* The direction (eccentricity, polar angle) of a click from the line of sight. */
void obs_click_direction(const person *p, const csf_response *ev, double *ecc, double *polar);
/* Waits for the click that says where the grating was; returns visual-angle x, y. */
csf_status obs_person_click(person *p, double *x_deg, double *y_deg, csf_error *err);
/* Text screen; a human reads it and presses a key (Escape = pause), a simulation moves on. */
csf_status obs_person_screen(person *p, const char *text, csf_error *err);
/* Escape during a human session: offer to resume or stop (data kept either way). Returns 1 to
 * resume (the interrupted trial is shown again), 0 to stop (the session is stored as paused). */
int obs_ask_resume(person *p, int done, int total);

#endif
