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

void csf_study_williams_row(int n, int row, int *out)
{
    if (n <= 0) return;
    int rows = n % 2 ? 2 * n : n;
    row = ((row % rows) + rows) % rows;
    int shift = row % n, mirror = row >= n;
    for (int j = 0; j < n; j++) {
        /* the first row 0, 1, n-1, 2, n-2, ...: every difference between neighbours once */
        int a = j == 0 ? 0 : j % 2 ? (j + 1) / 2 : n - j / 2;
        out[mirror ? n - 1 - j : j] = (a + shift) % n;
    }
}

int csf_study_latin_row(const csf_study *s, int participant_index, int *n_rows)
{
    int n = s->latin == CSF_LATIN_BLOCKS ? s->n_groups : s->latin == CSF_LATIN_CONDITIONS ? s->n_conds : 0;
    int rows = n <= 0 ? 1 : n % 2 ? 2 * n : n;
    if (n_rows) *n_rows = rows;
    return participant_index < 0 ? 0 : participant_index % rows;
}

/* Practice: conditions drawn from the practice pool (practice_conditions, or every condition),
 * the target shown so the person learns what to look for. */
static void plan_practice(const csf_study *s, csf_study_trial *t, uint64_t seed, int *pool)
{
    int n_pool = 0;
    for (int c = 0; c < s->n_conds; c++)
        if (s->conds[c].practice_pool) pool[n_pool++] = c;
    if (!n_pool) /* a study assembled in memory without its pool resolved: every condition */
        for (int c = 0; c < s->n_conds; c++) pool[n_pool++] = c;
    if (!n_pool) return; /* no conditions: nothing to practise (a parsed study has some) */
    for (int i = 0; i < s->practice_trials; i++) {
        t[i].cond = pool[csf_rng_u64(seed, ST_PRACTICE, (uint64_t)i) % (uint64_t)n_pool];
        t[i].block = -1;
        t[i].practice = 1;
        t[i].target = s->design == CSF_DESIGN_YES_NO || s->design == CSF_DESIGN_SAME_DIFF
                          ? (i % 2 == 0)
                          : (int)(csf_rng_u64(seed, ST_PRACTICE + 1, (uint64_t)i) % 2);
        t[i].order = (int)(csf_rng_u64(seed, ST_PRACTICE + 2, (uint64_t)i) % 2);
    }
}

/* Sequential order: m runs of `per` trials (one condition each) become m-long passes, the
 * conditions in their run order in each pass. */
static void interleave(csf_study_trial *t, int m, int per, csf_study_trial *scratch)
{
    for (int r = 0; r < per; r++)
        for (int j = 0; j < m; j++) scratch[r * m + j] = t[j * per + r];
    memcpy(t, scratch, (size_t)m * (size_t)per * sizeof *t);
}

typedef struct {
    int *tmp, *tmp2, *count, *corder, *border;
    csf_study_trial *scratch;
} plan_work;

static void plan_work_free(plan_work *w)
{
    free(w->tmp);
    free(w->tmp2);
    free(w->count);
    free(w->corder);
    free(w->border);
    free(w->scratch);
}

/* The main blocks from trial k on: each block's conditions (of its blocked_by value) in the
 * condition order, labelled, then shuffled or passed through in turn. Returns the next free k. */
static int plan_blocks(const csf_study *s, csf_study_trial *t, int k, int n_blocks, int per_block,
                       uint64_t seed, plan_work *w)
{
    for (int bi = 0; bi < n_blocks; bi++) {
        int start = k, m = 0;
        for (int j = 0; j < s->n_conds; j++) {
            int c = w->corder[j];
            if (s->blocked_by[0] && s->conds[c].group != w->border[bi]) continue;
            for (int i = 0; i < per_block; i++) {
                t[k + i].cond = c;
                t[k + i].block = bi;
            }
            label_block(s, &t[k], per_block, seed, (uint64_t)bi * CSF_STUDY_MAX_CONDITIONS + (uint64_t)c + 1,
                        w->tmp, w->tmp2);
            k += per_block;
            m++;
        }
        if (s->order == CSF_ORDER_SEQUENTIAL) interleave(&t[start], m, per_block, w->scratch);
        else shuffle(&t[start], k - start, seed, (uint64_t)bi);
    }
    return k;
}

csf_status csf_study_make_plan(const csf_study *s, uint64_t seed, int participant_index,
                               csf_study_trial **out, int *n, csf_error *err)
{
    *out = NULL;
    *n = 0;
    int blocked = s->blocked_by[0] != '\0';
    int n_blocks = blocked ? s->n_groups : s->blocks;
    int per_block = blocked ? s->trials_per_condition : s->trials_per_condition / s->blocks;
    long total = (long)s->practice_trials + (long)s->trials_per_condition * s->n_conds;
    if (total > 1000000)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %ld trials in one session (limit 1000000)", s->path,
                             total);
    size_t nc = (size_t)s->n_conds + 1, nb = (size_t)n_blocks + 1;
    csf_study_trial *t = calloc((size_t)total + 1, sizeof *t);
    plan_work w = {malloc((size_t)per_block * sizeof(int)),
                   malloc((size_t)per_block * sizeof(int)),
                   calloc(nc, sizeof(int)),
                   calloc(nc, sizeof(int)),
                   calloc(nb, sizeof(int)),
                   calloc((size_t)total + 1, sizeof(csf_study_trial))};
    if (!t || !w.tmp || !w.tmp2 || !w.count || !w.corder || !w.border || !w.scratch) {
        free(t);
        plan_work_free(&w);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    int row = csf_study_latin_row(s, participant_index, NULL);
    for (int c = 0; c < s->n_conds; c++) w.corder[c] = c;
    for (int b = 0; b < n_blocks; b++) w.border[b] = b;
    if (s->latin == CSF_LATIN_CONDITIONS) csf_study_williams_row(s->n_conds, row, w.corder);
    if (s->latin == CSF_LATIN_BLOCKS) csf_study_williams_row(n_blocks, row, w.border);
    plan_practice(s, t, seed, w.count);
    memset(w.count, 0, nc * sizeof(int));
    int k = plan_blocks(s, t, s->practice_trials, n_blocks, per_block, seed, &w);
    for (int i = s->practice_trials; i < k; i++) t[i].cond_trial = w.count[t[i].cond]++;
    plan_work_free(&w);
    *out = t;
    *n = k;
    return CSF_OK;
}
