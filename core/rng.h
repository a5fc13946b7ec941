/* Counter-based random numbers: every draw is a pure function of (seed, stream, index).
 * Why: a simulated session killed and resumed must draw exactly what an uninterrupted run drew,
 * without persisting generator state. Derive the index from the trial number (and a sub-index for
 * draws within a trial), and the stream from what is being drawn (noise, lapse, timing ...). */
#ifndef CSF_RNG_H
#define CSF_RNG_H

#include <stdint.h>

uint64_t csf_rng_u64(uint64_t seed, uint64_t stream, uint64_t index);
/* Uniform in the open interval (0, 1). */
double csf_rng_uniform(uint64_t seed, uint64_t stream, uint64_t index);
/* Standard normal (mean 0, sd 1) by inverse transform of one uniform, so it costs one index. */
double csf_rng_normal(uint64_t seed, uint64_t stream, uint64_t index);

/* A sequential generator for places where a counter would be awkward (benchmarks, Monte Carlo in
 * fits). Still fully determined by its seed. */
typedef struct {
    uint64_t seed, stream, next;
} csf_rng;

void csf_rng_init(csf_rng *r, uint64_t seed, uint64_t stream);
uint64_t csf_rng_next_u64(csf_rng *r);
double csf_rng_next_uniform(csf_rng *r);
double csf_rng_next_normal(csf_rng *r);

#endif
