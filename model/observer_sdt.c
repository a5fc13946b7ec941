/* Signal-detection decision model (see observer_sdt.h). */
#include "model/observer_sdt.h"

#include "model/psychometric.h"

#include <math.h>

double csf_sdt_phi(double x)
{
    return exp(-0.5 * x * x) / sqrt(2.0 * M_PI);
}

double csf_sdt_Phi(double x)
{
    return 0.5 * erfc(-x / sqrt(2.0));
}

double csf_sdt_dprime(double contrast, double threshold, double k)
{
    if (!(contrast > 0) || !isfinite(threshold) || !(threshold > 0)) return 0.0;
    return CSF_SDT_D_AT_T * pow(contrast / threshold, k);
}

/* The integral lives with the methods' models (model/psychometric.c), so observer and methods
 * share one definition of the task-independent threshold. */
double csf_sdt_pc_mafc(double dprime, int m)
{
    return csf_psy_sdt_pc_mafc(dprime, m);
}

double csf_sdt_dprime_for_pc(double p, int m)
{
    if (m < 2 || m > 64 || !(p > 1.0 / m) || !(p < 1)) return NAN;
    double lo = 0, hi = 40;
    for (int i = 0; i < 80; i++) {
        double mid = 0.5 * (lo + hi);
        if (csf_sdt_pc_mafc(mid, m) < p) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}
