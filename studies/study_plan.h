/* The trial sequence of one participant's session: a pure function of the study and the
 * participant's seed, so a resumed session and the report rebuild exactly the sequence that ran
 * (the store keeps the study files, the seed and the trials; trial seq i is plan entry i).
 *
 * Order: practice trials first (conditions drawn at random from practice_conditions, or from all,
 * at an easy level), then `blocks` blocks; each block holds trials_per_condition / blocks trials
 * of every condition, shuffled (Fisher-Yates, core/rng.h keyed by the seed), or with order =
 * sequential the conditions in turn, one trial each per pass. With blocked_by = COLUMN there is
 * one block per value of that column, holding all trials of its conditions. counterbalance =
 * latin_blocks orders those blocks, latin_conditions the conditions of a sequential pass, by the
 * participant's row of a balanced Latin square. Counterbalancing (counterbalance = yes): within
 * each condition and block the target place/interval (2afc, 2ifc), the pair order (same/different)
 * and target-present trials (yes/no) are split as evenly as the count allows; the odd one out is
 * drawn from the seed. */
#ifndef CSF_STUDY_PLAN_H
#define CSF_STUDY_PLAN_H

#include <stdint.h>

#include "studies/study_file.h"

typedef struct {
    int cond;        /* index into study->conds */
    int block;       /* 0-based; -1 for practice */
    int practice;
    int target;      /* 2afc/2ifc: place/interval of the target (0, 1); yes/no: 1 present, 0
                        catch; same/different: 1 different pair, 0 same pair */
    int order;       /* same/different: 0 image_a first, 1 image_b first (different pairs);
                        same pairs: 0 = a,a  1 = b,b. 2afc/2ifc images: unused (target holds b) */
    int cond_trial;  /* 0-based index among the condition's main trials (adaptive procedures) */
} csf_study_trial;

/* The participant's seed: the study's seed mixed with the participant code (so participants get
 * different orders, and the same participant the same order on resume). */
uint64_t csf_study_participant_seed(const csf_study *s, const char *participant);

/* Row `row` of a balanced Latin square over n items (Williams 1949): out[j] is the j-th item shown.
 * Each item is in each position once over n rows, and with even n each item follows every other
 * exactly once; odd n needs 2n rows (the square and its mirror) for that, so rows are taken modulo
 * n (even) or 2n (odd). */
void csf_study_williams_row(int n, int row, int *out);

/* The Latin-square row of a participant's index (0 for a study without counterbalance = latin_*),
 * and how many rows the square has (1 without). */
int csf_study_latin_row(const csf_study *s, int participant_index, int *n_rows);

/* *out malloc'd (free()), *n entries. participant_index: the participant's place in the order of
 * the version's first sessions (0-based, stored with the session), which picks the Latin-square
 * row; unused without counterbalance = latin_*. */
csf_status csf_study_make_plan(const csf_study *s, uint64_t seed, int participant_index,
                               csf_study_trial **out, int *n, csf_error *err);

#endif
