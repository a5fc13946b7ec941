/* The experimenter's view of an observer session: on a terminal, one line on stderr updated in
 * place after every trial (a person's session) or every tenth (a simulated one), saying the
 * trial and the budget (or the precision reached against the target), the cells settled, the
 * person's time so far and the time left at the run's own pace, and the latest pause or flagged
 * trial. When stderr is not a terminal (a log, a pipe) nothing is redrawn: the session's periodic
 * lines stand alone, as before. Silent with --quiet (and so with --json). */
#ifndef CSF_OBSERVER_PROGRESS_H
#define CSF_OBSERVER_PROGRESS_H

typedef struct {
    int live;            /* stderr is a terminal and the session is not quiet */
    int on_screen;       /* a line is drawn and not yet ended */
    char last_event[96]; /* the latest pause or flagged trial, "" when none */
} obs_progress;

typedef struct {
    int trial, budget;        /* main trials done, and the budget (or cap) */
    double rms_log10, target; /* the predicted error and the --precision target (0: none) */
    int cells_settled, cells; /* cells whose stated error is at or below the settle level */
    double settle_log10;      /* that level: the target, or 0.15 with a fixed budget */
    double spent_s, left_s;   /* the person's time so far and left (NAN: not known yet) */
} obs_progress_state;

/* --precision: the trials still to run, for a session whose predicted error is rms_log10 after n
 * main trials, to reach target_log10 within cap: the error falls about as 1/sqrt(trials), so
 * n (rms/target)^2 in all (from simulated sessions, at 50-150 trials that is within 1.5x of the
 * trials the stop then takes for two people in three). 0 once reached; -1 when not known yet. */
int obs_progress_trials_left(int n, double rms_log10, double target_log10, int cap);

/* live: whether to draw (a terminal, not quiet); the caller decides, so tests can ask for it. */
void obs_progress_init(obs_progress *p, int live);
/* The latest event, shown on the next line drawn (printf-like; a trial number included). */
void obs_progress_event(obs_progress *p, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Redraws the line. */
void obs_progress_show(obs_progress *p, const obs_progress_state *s);
/* Ends a drawn line with a newline, so what is printed next starts on its own. */
void obs_progress_end(obs_progress *p);

#endif
