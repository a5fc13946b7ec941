/* A simulated person judging same/different on pairs of moving sequences, for the example's own
 * check (README.md, "The moving check"). It is a model with noise, not a rule with an answer: per
 * trial the pair is the same sequence twice or the reference and the candidate (half each); the
 * person's internal difference signal is d' = V^k (signal-detection transducer, Foley & Legge
 * 1981: k = 2.5) when they differ and 0 when not, plus unit Gaussian noise, and the answer is
 * "different" above a fixed criterion of 1 (the person does not know d'); a lapse rate of 2 %
 * answers at random. V is the sequence's visibility in threshold units (the spatio-temporal rule
 * of imgdiff.h at each pixel's retinal velocity; frames within 100 ms averaged, windows pooled
 * by probability summation: sequence.c), so a pair below threshold
 * gives d' near 0 and chance performance, whatever the criterion. */
#ifndef LOD_JUDGE_H
#define LOD_JUDGE_H

#include <stdint.h>

typedef struct {
    int trials, correct;
    double dprime; /* the model's d' for the differing pairs */
    double p_correct;
    double p_above_chance; /* exact one-sided binomial P(X >= correct | trials, 0.5) */
} lod_judgement;

/* visibility: V >= 0; seed and key select the noise (the same seed and key give the same answers). */
void lod_judge_same_different(double visibility, int trials, uint64_t seed, uint64_t key, lod_judgement *out);

#endif
