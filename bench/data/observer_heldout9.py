#!/usr/bin/env python3
"""Writes the NINTH held-out truths of bench_observer --honest --heldout 9, and prints
the observer specs the bench compiles in (bench/bench_observer.c, HONEST_NINTH).

Made on 2026-11-27 at 18:05 UTC, after the eighth set had measured the shipped method and before
any later change to the method: nothing is tuned on them; they are to be run once, on the method
as the next change leaves it. None is of the parametric form the bayes method and the QUEST+
anchor fit, and the shapes differ from every earlier set.

observer_daly.csv -- Daly's (1993) visible-differences-predictor CSF at 50 cd/m^2 (the form
  S(f) = P ((3.23 (f^2)^-0.3)^5 + 1)^-0.2 A e f exp(-B e f) sqrt(1 + 0.06 exp(B e f)),
  A = 0.801 (1 + 0.7 / L)^-0.2, B = 0.3 (1 + 100 / L)^0.15, e = 0.9, P = 250), its low-frequency
  roll-off from the first factor rather than Barten's lateral inhibition; the periphery loses a
  fixed amount per period of eccentricity with a sub-linear exponent, log10 loss 0.035 (f e)^0.8
  (sensitivity scaled in cycles of eccentricity, as Pointer & Hess 1989 describe, with the
  slower-than-linear growth of their far periphery).
observer_glaucoma.csv -- Barten's simplified CSF (1999) at 100 cd/m^2, 4 deg field, with an
  ordinary peripheral loss, log10 (0.02 + 0.01 f) e^0.9, and an arcuate mid-peripheral
  depression of early glaucoma: a further 0.35 exp(-((e - 13) / 5)^2) log10 at every frequency,
  so the 10 deg ring sits below the 20 deg ring at low frequencies while the fovea is normal.
observer_fewcycles.csv -- Barten's simplified CSF at 30 cd/m^2, 2 deg field, with the
  number-of-cycles effect of a Gabor of fixed size (sigma 1 deg, as the session draws): about
  n = 2.5 f cycles are inside +-1.25 sigma, and below n_sat = 7 cycles sensitivity falls as
  (n / n_sat)^0.5 (Hoekstra et al. 1974; Savoy & McCann 1975), so the low frequencies lose up to
  0.37 log10; eccentricity loss saturating with distance, log10 0.5 (1 - exp(-e / 10)) (1 + f / 4).
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 202611279, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout9.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 202611279


def daly0(f, lum=50.0):
    eps, peak = 0.9, 250.0
    a = 0.801 * (1.0 + 0.7 / lum) ** -0.2
    b = 0.3 * (1.0 + 100.0 / lum) ** 0.15
    low = ((3.23 * (f * f) ** -0.3) ** 5 + 1.0) ** -0.2
    return peak * low * a * eps * f * math.exp(-b * eps * f) * math.sqrt(1.0 + 0.06 * math.exp(b * eps * f))


def daly(f, e):
    return daly0(f) * 10 ** (-0.035 * (f * e) ** 0.8)


def glaucoma(f, e):
    loss = (0.02 + 0.01 * f) * e ** 0.9 + 0.35 * math.exp(-(((e - 13.0) / 5.0) ** 2))
    return barten(f, 100.0, 4.0) * 10 ** -loss


def fewcycles(f, e):
    n = 2.5 * f * 1.0
    cycles = min(1.0, (n / 7.0) ** 0.5)
    return barten(f, 30.0) * cycles * 10 ** (-0.5 * (1.0 - math.exp(-e / 10.0)) * (1.0 + f / 4.0))


TRUTHS = (("daly", daly), ("glaucoma", glaucoma), ("fewcycles", fewcycles))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
