/* Trial sequence of a study session (see study_plan.h). */
#include "studies/study_plan.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"

enum { ST_SHUFFLE = 0x57d1, ST_ODD, ST_PRACTICE };

uint64_t csf_study_participant_seed(const csf_study *s, const char *participant)
{
    /* 53 bits: the seed travels in JSON, whose numbers are doubles */
    return csf_fnv1a64(participant, strlen(participant), s->seed ^ CSF_FNV1A64_INIT) & ((1ULL << 53) - 1);
}

/* Balanced binary labels for n trials with a share p of ones: round(n p) ones, the fractional
 * remainder decided by one draw. */
static void balanced(int *v, int n, double p, uint64_t seed, uint64_t key)
{
    double want = n * p;
    int ones = (int)floor(want);
    if (csf_rng_uniform(seed, ST_ODD, key) < want - ones) ones++;
    for (int i = 0; i < n; i++) v[i] = i < ones;
}

static void shuffle(csf_study_trial *t, int n, uint64_t seed, uint64_t stream_key)
{
    for (int i = n - 1; i > 0; i--) {
        int j = (int)(csf_rng_u64(seed, ST_SHUFFLE + stream_key, (uint64_t)i) % (uint64_t)(i + 1));
        csf_study_trial tmp = t[i];
        t[i] = t[j];
        t[j] = tmp;
    }
}

/* Labels of one condition's trials in one block. */
static void label_block(const csf_study *s, csf_study_trial *t, int n, uint64_t seed, uint64_t key,
                        int *tmp, int *tmp2)
{
    double p_target = s->design == CSF_DESIGN_YES_NO ? 1 - s->catch_fraction
                    : s->design == CSF_DESIGN_SAME_DIFF ? 1 - s->same_fraction : 0.5;
    if (s->counterbalance || s->design == CSF_DESIGN_YES_NO || s->design == CSF_DESIGN_SAME_DIFF) {
        balanced(tmp, n, p_target, seed, key * 2);
    } else {
        for (int i = 0; i < n; i++) tmp[i] = csf_rng_uniform(seed, ST_ODD, key * 1000 + (uint64_t)i) < 0.5;
    }
    if (s->counterbalance) balanced(tmp2, n, 0.5, seed, key * 2 + 1);
    else
        for (int i = 0; i < n; i++) tmp2[i] = csf_rng_uniform(seed, ST_ODD + 7, key * 1000 + (uint64_t)i) < 0.5;
    /* order balanced independently of the target: shuffle the order labels first */
    for (int i = n - 1; i > 0; i--) {
        int j = (int)(csf_rng_u64(seed, ST_ODD + 11, key * 1000 + (uint64_t)i) % (uint64_t)(i + 1));
        int x = tmp2[i];
        tmp2[i] = tmp2[j];
        tmp2[j] = x;
    }
    for (int i = 0; i < n; i++) {
        t[i].target = tmp[i];
        t[i].order = tmp2[i];
    }
}

csf_status csf_study_make_plan(const csf_study *s, uint64_t seed, csf_study_trial **out, int *n,
                               csf_error *err)
{
    *out = NULL;
    *n = 0;
    int per_block = s->trials_per_condition / s->blocks;
    long total = (long)s->practice_trials + (long)s->trials_per_condition * s->n_conds;
    if (total > 1000000)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %ld trials in one session (limit 1000000)",
                             s->path, total);
    csf_study_trial *t = calloc((size_t)total, sizeof *t);
    int *tmp = malloc((size_t)per_block * sizeof *tmp), *tmp2 = malloc((size_t)per_block * sizeof *tmp2);
    int *count = calloc((size_t)s->n_conds, sizeof *count);
    if (!t || !tmp || !tmp2 || !count) {
        free(t);
        free(tmp);
        free(tmp2);
        free(count);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    int k = 0;
    for (int i = 0; i < s->practice_trials; i++, k++) {
        t[k].cond = (int)(csf_rng_u64(seed, ST_PRACTICE, (uint64_t)i) % (uint64_t)s->n_conds);
        t[k].block = -1;
        t[k].practice = 1;
        /* practice shows the target: the person learns what to look for */
        t[k].target = s->design == CSF_DESIGN_YES_NO || s->design == CSF_DESIGN_SAME_DIFF
                          ? (i % 2 == 0) : (int)(csf_rng_u64(seed, ST_PRACTICE + 1, (uint64_t)i) % 2);
        t[k].order = (int)(csf_rng_u64(seed, ST_PRACTICE + 2, (uint64_t)i) % 2);
    }
    for (int b = 0; b < s->blocks; b++) {
        int start = k;
        for (int c = 0; c < s->n_conds; c++) {
            for (int i = 0; i < per_block; i++) {
                t[k + i].cond = c;
                t[k + i].block = b;
            }
            label_block(s, &t[k], per_block, seed, (uint64_t)b * CSF_STUDY_MAX_CONDITIONS + (uint64_t)c + 1,
                        tmp, tmp2);
            k += per_block;
        }
        shuffle(&t[start], k - start, seed, (uint64_t)b);
    }
    for (int i = s->practice_trials; i < k; i++) t[i].cond_trial = count[t[i].cond]++;
    free(tmp);
    free(tmp2);
    free(count);
    *out = t;
    *n = k;
    return CSF_OK;
}
