/* Answers of the simulated observer to one fixed-level study curve, shared by the study benches
 * (bench_study_coverage, bench/anchors/anchor_data) so both measure the same data. */
#ifndef CSF_BENCH_SIM_STUDY_H
#define CSF_BENCH_SIM_STUDY_H

#include <stdint.h>

#include "model/observer_sim.h"
#include "studies/study_stats.h"

/* One yes/no trial through the fade-in observer: contrast c (0 = catch) for 0.3 s, then 1.5 s of
 * blank at 60 Hz, as `csfcal study run` shows it; 1 = "yes". */
int sim_study_yes_no_trial(const csf_observer_sim *o, uint64_t trial, double freq_cpd, double ecc_deg,
                           double contrast);

/* Fills lv[0..n_levels-1]: levels 0.15 log10 apart from t_true_log10 - 0.45, trials_per_level
 * each; 2AFC by location (target place alternating) or yes/no with catch_per_level catch trials
 * after each level, their false alarms added to *false_alarms and counted in *n_catch. *trial
 * numbers the observer's draws and advances. */
void sim_study_levels(const csf_observer_sim *o, uint64_t *trial, double freq_cpd, double ecc_deg,
                      double t_true_log10, int n_levels, int trials_per_level, int yes_no, int catch_per_level,
                      csf_psy_level *lv, int *false_alarms, int *n_catch);

#endif
