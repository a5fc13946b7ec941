#!/usr/bin/env python3
"""Writes the FIFTEENTH held-out truths of bench_observer --honest --heldout 15, and
prints the observer specs the bench compiles in (bench/bench_observer.c, HONEST_FIFTEENTH).

Made on 2026-11-28 at 07:02 UTC, after the fourteenth set had judged the foveal term freed only
with four places (not adopted), and before any later change to the method: nothing is tuned on
them; they are to be run once, on the method as the next change leaves it. None is of the
parametric form the bayes method and the QUEST+ anchor fit. They were chosen for the spread of
real observers: a loss at high frequencies everywhere, a notch at middle frequencies, and a
periphery poorer than normal at middle frequencies only.

observer_diabetic.csv -- early diabetic retinopathy without maculopathy (after Della Sala et al.
  1985 and Sokol et al. 1985): Barten's CSF at 80 cd/m^2, 10 deg field, losing log10
  0.2 / (1 + exp(-(log2 f - 1.5) / 0.6)) at every eccentricity (middle and high frequencies);
  the periphery loses log10 0.012 f e + 0.008 e.
observer_parkinson.csv -- Parkinson's disease (after Bodis-Wollner et al. 1987 and Regan & Maxner
  1987): Barten at 100 cd/m^2, 10 deg field, a notch of log10 0.3 exp(-(log2(f / 3) / 0.9)^2)
  at every eccentricity; the periphery loses log10 0.01 f e + 0.01 e.
observer_migraine.csv -- migraine between attacks (after McKendrick et al. 2000 and 2001): Barten
  at 100 cd/m^2, 10 deg field; the periphery loses log10 0.01 f e + 0.012 e plus
  0.15 (1 - exp(-e / 10)) exp(-(log2(f / 2) / 1.2)^2), a loss at middle frequencies that grows
  outwards.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026112815, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout15.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 2026112815


def diabetic(f, e):
    loss = 0.2 / (1.0 + math.exp(-(math.log2(f) - 1.5) / 0.6)) + 0.012 * f * e + 0.008 * e
    return barten(f, 80.0, 10.0) * 10 ** -loss


def parkinson(f, e):
    notch = 0.3 * math.exp(-((math.log2(f / 3.0) / 0.9) ** 2))
    return barten(f, 100.0, 10.0) * 10 ** -(notch + 0.01 * f * e + 0.01 * e)


def migraine(f, e):
    mid = 0.15 * (1.0 - math.exp(-e / 10.0)) * math.exp(-((math.log2(f / 2.0) / 1.2) ** 2))
    return barten(f, 100.0, 10.0) * 10 ** -(0.01 * f * e + 0.012 * e + mid)


TRUTHS = (("diabetic", diabetic), ("parkinson", parkinson), ("migraine", migraine))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
