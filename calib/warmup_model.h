/* When is a display warm? A display's light settles after power-on along an exponential approach
 * w(t) = A + B e^(-t/tau) (Brainard, Pelli & Robson 2002 advise measuring only once it has
 * settled; the calibration's drift correction uses the same curve). The judgement fits that model
 * to the white readings and asks how much more the white will move during the session that
 * depends on it; a display is warm when that is below the asked accuracy.
 *
 * The model is trusted only when the readings show a drift at all: it must explain them
 * significantly better than a constant (the extra-sum-of-squares F test at 1 %, as for nested
 * nonlinear models in Bates & Watts 1988). Without a visible drift the judgement is the step test
 * alone (the mean of the last three readings against the three before), which a display that is
 * already warm passes after six readings. The step test is required in every case, so a model
 * that fits a settled display's noise never calls it warm earlier than the step test would. */
#ifndef CSF_WARMUP_MODEL_H
#define CSF_WARMUP_MODEL_H

typedef struct {
    /* 1: the step test passes and the model (when significant) predicts less than target_rel of
     * drift over the session */
    int warm;
    int step_settled;             /* the step test alone (csf_display_warm_settled) */
    int model_significant;        /* the exponential explains the readings better than a constant */
    double change_rel;            /* the step test's relative change (NAN under 6 readings) */
    double A_cdm2, B_cdm2, tau_s; /* the fitted model, t from the first reading (NAN: no fit) */
    /* predicted |white change| from the last reading over session_s, relative to white then (0
     * when the model is not significant) */
    double remaining_rel;
    /* predicted |white - A| / white at the last reading: how far the white still is from where it
     * settles (0 when the model is not significant) */
    double settled_gap_rel;
    /* predicted time from the last reading until remaining_rel falls below target_rel (0 when it
     * already has; INFINITY when the model puts white at or below zero) */
    double wait_s;
} csf_warm_judgement;

/* The session a warm-up protects by default: one hour, the usual length of a psychophysics
 * session (observer fatigue limits it) and of a set of calibration and verification runs. */
#define CSF_WARM_SESSION_S 3600.0

/* Judges the n white readings w_cdm2 taken at times t_s (seconds, any origin, increasing).
 * target_rel: the accuracy asked for (the profile's target); session_s: how long the white must
 * hold. Returns j->warm. */
int csf_display_warm_judge(const double *t_s, const double *w_cdm2, int n, double target_rel,
                           double session_s, csf_warm_judgement *j);

/* The sample sd of x[0..n-1] (0 for one value): the spread of repeated readings that the step
 * test, calibration's noise estimates and verification's reading noise take. */
double csf_sample_sd(const double *x, int n);

/* Least-squares fit of y = A + B e^(-t/tau): tau on a log grid (1 s x 1.15^k, k = 0..64, up to
 * about 2 hours) refined between the grid's neighbours, A and B linear. t is used as given
 * (callers choose the origin). Returns 0 and the residual sum of squares in *sse, or -1 when no
 * tau gives a well-conditioned fit. */
int csf_exp_settle_fit(const double *t_s, const double *y, int n, double *A, double *B, double *tau_s,
                       double *sse);

#endif
