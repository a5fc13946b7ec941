/* The state of one observer session while it runs, shared by the files of the observer
 * procedure (observer_calib.c runs the phases, observer_table.c judges the data and writes the
 * table). Internal to the procedure: callers see csf_obs_session through observer_session.h. */
#ifndef CSF_OBSERVER_RUN_H
#define CSF_OBSERVER_RUN_H

#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include "calib/observer_progress.h"
#include "calib/observer_session.h"
#include "calib/observer_trials.h"
#include "calib/procedure.h"

typedef csf_obs_settings session_settings;

/* What a session works with: the resources its command lent it (store, presenter, profile, the
 * person's side; never closed here) and what it made itself (the method, cells, layouts). */
typedef struct {
    csf_store *store;
    csf_presenter *pres;
    csf_display_profile *profile;
    csf_observer_sim *sim;
    csf_responder *resp;
    const csf_procedure_ops *ops;
    void *proc;
    csf_trial *stored;
    csf_cell *cells;
    csf_cell_estimate *est;
    csf_afc_layout *layouts;  /* per cell: four places or two intervals */
    int *n_alt;               /* per cell: 2 or 4 (the procedure setup's n_alternatives) */
    unsigned char *not_shown; /* per cell: 1 = its drift would alias on this display (never shown) */
    csf_obs_screen *screen;   /* view=frame: the simulated person's eyes on the presenter */
} session_res;

/* Everything one session holds while it runs: what it was asked, what it was lent, its settings
 * and where it stands. Each phase below takes it; observer_session.h's calls run them in order. */
struct csf_obs_session {
    const csf_obs_options *opt;
    const csf_config *cfg;
    csf_obs_result *res;
    session_res S;
    session_settings set;
    csf_geometry geom;
    int64_t sid; /* 0 until the store has the session (a new one) */
    uint64_t seed;
    int resume_n_stored; /* trials the store held when a resumed session began */
    int said_paused;     /* the pause message already names --resume */
    int is_sim, is_human;
    double mean_lum_cdm2, max_contrast;
    int n_cells;
    size_t n_stored;            /* trials in S.stored, practice included */
    csf_afc_layout prac_layout; /* the four-place practice grating's places (2: none) */
    double prac_ecc_deg;
    person who;
    runner run;
    int seq;               /* the next trial's sequence number */
    int trial_index;       /* the next main trial's index */
    int default_budget;    /* the budget is the default for this grid (set once the display is known) */
    int n_not_shown;       /* cells whose drift this display cannot show */
    double person_t0_s;    /* presenter clock when this run's first trial began */
    int person_started;    /* person_t0_s is set: the first screen was shown */
    int resume_done;       /* main trials stored before this run (a resume) */
    int person_recorded;   /* this run's person time is in the store */
    obs_progress progress; /* the experimenter's line on a terminal */
    struct timespec wall0; /* when the session began, for the wall time of the result */
};
typedef struct csf_obs_session obs_run;

/* Whether the person's data can support a table; CSF_E_INSUFFICIENT says why not. */
csf_status obs_judge_session(obs_run *R, csf_error *err);
/* The threshold table, written and kept in the store as an artifact. */
csf_status obs_write_table(obs_run *R, csf_error *err);
/* The session finished; its plot, when asked for, written and kept as an artifact. */
csf_status obs_finish_session(obs_run *R, csf_error *err);
/* The root mean square of the stated errors (log10) over the visible cells shown: the table's
 * predicted error. NaN without such a cell. */
double obs_rms_of_estimates(const obs_run *R);
/* The current time as ISO 8601 UTC. */
void obs_now_utc(char *buf, size_t len);

#endif
