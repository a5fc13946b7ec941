/* Signal-detection decision model of the simulated observer (model/observer_sim.h,
 * decision=sdt). Pure functions, no state.
 *
 * Transducer: d'(c) = CSF_SDT_D_AT_T * (c / t)^k. The table's threshold t is therefore the
 * contrast where two-interval P(correct) (no lapse) is 1 - e^-1/2 = 81.6 %, exactly where the
 * high-threshold Weibull of model/psychometric.h puts its t in 2AFC, so one truth table means the
 * same in the two-interval task under either model. The power-law form d' = (c / t')^k (Legge &
 * Foley 1980) has t' = t * CSF_SDT_D_AT_T^(-1/k) (d' = 1 there; 2AFC P = 76.0 %).
 * m-AFC: P(correct | d') = integral phi(x - d') Phi(x)^(m-1) dx (the signal's response is the
 * largest of m unit-variance Gaussians). At t: 2AFC 81.6 %, 4AFC 63.1 %; the 4AFC 72.4 % point
 * (the Weibull's t in four places) is at d' = 1.582, i.e. 0.094 / k log10 above t. */
#ifndef CSF_OBSERVER_SDT_H
#define CSF_OBSERVER_SDT_H

/* d' at the threshold: sqrt(2) * Phi^-1(1 - e^-1 / 2); the table's task-independent criterion
 * (CSF_PSY_DPRIME_CRITERION in model/psychometric.h, where the methods use it). */
#define CSF_SDT_D_AT_T 1.2734322744392470

/* d' of a Michelson contrast c at threshold t with transducer exponent k (0 for c <= 0; 0 for
 * an infinite t, never visible). */
double csf_sdt_dprime(double contrast, double threshold, double k);
/* P(correct) of the max rule in m-AFC (2 <= m <= 64) at d' (numeric integral, |error| < 1e-9). */
double csf_sdt_pc_mafc(double dprime, int m);
/* The d' at which csf_sdt_pc_mafc(d', m) = p (1/m < p < 1); NAN outside. */
double csf_sdt_dprime_for_pc(double p, int m);
/* Standard normal pdf and cdf. */
double csf_sdt_phi(double x);
double csf_sdt_Phi(double x);

#endif
