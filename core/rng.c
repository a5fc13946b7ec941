#include "core/rng.h"

#include <math.h>

/* splitmix64 finaliser: a bijective mixer with good avalanche, enough for simulation noise. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

uint64_t csf_rng_u64(uint64_t seed, uint64_t stream, uint64_t index)
{
    uint64_t h = mix64(seed + 0x9e3779b97f4a7c15ULL);
    h = mix64(h ^ (stream * 0xd6e8feb86659fd93ULL + 0x632be59bd9b4e019ULL));
    return mix64(h ^ (index * 0x9e3779b97f4a7c15ULL + 0x1234567ULL));
}

double csf_rng_uniform(uint64_t seed, uint64_t stream, uint64_t index)
{
    /* 53 random bits, shifted by half a step so 0 and 1 are never returned. */
    uint64_t bits = csf_rng_u64(seed, stream, index) >> 11;
    return ((double)bits + 0.5) * (1.0 / 9007199254740992.0);
}

/* Acklam's rational approximation of the normal quantile (rel. error < 1.2e-9). */
static double normal_quantile(double p)
{
    static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                               -2.759285104469687e+02, 1.383577518672690e+02,
                               -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                               -1.556989798598866e+02, 6.680131188771972e+01,
                               -1.328068155288572e+01};
    static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                               -2.400758277161838e+00, -2.549732539343734e+00,
                               4.374664141464968e+00,  2.938163982698783e+00};
    static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                               2.445134137142996e+00, 3.754408661907416e+00};
    const double plow = 0.02425, phigh = 1 - plow;
    if (p < plow) {
        double q = sqrt(-2 * log(p));
        return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
               ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    }
    if (p > phigh) {
        double q = sqrt(-2 * log(1 - p));
        return -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
               ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    }
    double q = p - 0.5, r = q * q;
    return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
           (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
}

double csf_rng_normal(uint64_t seed, uint64_t stream, uint64_t index)
{
    return normal_quantile(csf_rng_uniform(seed, stream, index));
}

void csf_rng_init(csf_rng *r, uint64_t seed, uint64_t stream)
{
    r->seed = seed;
    r->stream = stream;
    r->next = 0;
}

uint64_t csf_rng_next_u64(csf_rng *r) { return csf_rng_u64(r->seed, r->stream, r->next++); }
double csf_rng_next_uniform(csf_rng *r) { return csf_rng_uniform(r->seed, r->stream, r->next++); }
double csf_rng_next_normal(csf_rng *r) { return csf_rng_normal(r->seed, r->stream, r->next++); }
