#include "sim_study.h"

#include <math.h>

int sim_study_yes_no_trial(const csf_observer_sim *o, uint64_t trial, double freq_cpd, double ecc_deg,
                           double contrast)
{
    const double period_s = 1.0 / 60;
    const int n_stim = 18, n_total = 18 + 90;
    csf_sim_fade_trial tr;
    csf_observer_sim_fade_begin(o, trial, freq_cpd, ecc_deg, 0, 0, n_total * period_s, &tr);
    for (int i = 0; i < n_total; i++) {
        double press;
        if (csf_observer_sim_fade_frame(o, &tr, i * period_s, i < n_stim ? contrast : 0, &press)) return 1;
    }
    return 0;
}

void sim_study_levels(const csf_observer_sim *o, uint64_t *trial, double freq_cpd, double ecc_deg,
                      double t_true_log10, int n_levels, int trials_per_level, int yes_no, int catch_per_level,
                      csf_psy_level *lv, int *false_alarms, int *n_catch)
{
    for (int i = 0; i < n_levels; i++) {
        lv[i].x_log10 = t_true_log10 - 0.45 + 0.15 * i;
        lv[i].n = trials_per_level;
        lv[i].k = 0;
        double c = pow(10.0, lv[i].x_log10);
        for (int j = 0; j < trials_per_level; j++, (*trial)++) {
            if (yes_no) {
                lv[i].k += sim_study_yes_no_trial(o, *trial, freq_cpd, ecc_deg, c);
                continue;
            }
            int target = (int)(*trial & 1);
            double shown[2] = {0, 0}, rt_s;
            shown[target] = c;
            lv[i].k += csf_observer_sim_2afc(o, *trial, freq_cpd, ecc_deg, shown, &rt_s) == target;
        }
        for (int j = 0; yes_no && j < catch_per_level; j++, (*trial)++, (*n_catch)++)
            *false_alarms += sim_study_yes_no_trial(o, *trial, freq_cpd, ecc_deg, 0);
    }
}
