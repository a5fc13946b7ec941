#include "judge.h"

#include <math.h>

#define JUDGE_TRANSDUCER_K 2.5
#define JUDGE_CRITERION 1.0
#define JUDGE_LAPSE 0.02

/* splitmix64 (Steele et al. 2014): a keyed stream, so each condition's noise is its own */
static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *s)
{
    return ((double)(next_u64(s) >> 11) + 0.5) / 9007199254740992.0;
}

static double gauss(uint64_t *s)
{
    return sqrt(-2 * log(uniform(s))) * cos(2 * 3.14159265358979323846 * uniform(s));
}

/* P(X >= k) for X ~ Binomial(n, 1/2), summed in logs so that n up to 1e5 does not underflow early */
static double binomial_upper_half(int n, int k)
{
    if (k <= 0) return 1;
    double p = 0, log_half_n = n * log(0.5);
    for (int j = k; j <= n; j++)
        p += exp(lgamma(n + 1.0) - lgamma(j + 1.0) - lgamma(n - j + 1.0) + log_half_n);
    return p > 1 ? 1 : p;
}

void lod_judge_same_different(double visibility, int trials, uint64_t seed, uint64_t key, lod_judgement *out)
{
    uint64_t s = seed * 0xD1B54A32D192ED03ull ^ key;
    double dprime = pow(visibility > 0 ? visibility : 0, JUDGE_TRANSDUCER_K);
    int correct = 0;
    for (int i = 0; i < trials; i++) {
        int differ = uniform(&s) < 0.5;
        int says_differ;
        if (uniform(&s) < JUDGE_LAPSE) says_differ = uniform(&s) < 0.5;
        else says_differ = (differ ? dprime : 0) + gauss(&s) > JUDGE_CRITERION;
        correct += says_differ == differ;
    }
    *out = (lod_judgement){.trials = trials,
                           .correct = correct,
                           .dprime = dprime,
                           .p_correct = trials ? (double)correct / trials : 0,
                           .p_above_chance = binomial_upper_half(trials, correct)};
}
