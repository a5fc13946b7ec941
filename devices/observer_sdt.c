/* Signal-detection decision model (see observer_sdt.h). */
#include "devices/observer_sdt.h"

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

/* Composite Simpson over [min(-9, d-9), max(9, d+9)]: the integrand is smooth and outside that
 * range below 1e-18, so 2000 panels are far inside 1e-9. */
double csf_sdt_pc_mafc(double dprime, int m)
{
    if (m < 2 || m > 64 || isnan(dprime)) return NAN;
    if (dprime > 40) return 1.0;
    double lo = fmin(-9.0, dprime - 9.0), hi = fmax(9.0, dprime + 9.0);
    const int n = 2000;
    double h = (hi - lo) / n, s = 0;
    for (int i = 0; i <= n; i++) {
        double x = lo + i * h;
        double w = (i == 0 || i == n) ? 1 : (i & 1) ? 4 : 2;
        s += w * csf_sdt_phi(x - dprime) * pow(csf_sdt_Phi(x), m - 1);
    }
    double p = s * h / 3;
    return p > 1 ? 1 : p;
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
