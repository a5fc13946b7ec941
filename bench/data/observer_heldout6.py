#!/usr/bin/env python3
"""Writes the SIXTH held-out truths of bench_observer --honest --heldout 6, and prints
the observer specs the bench compiles in (bench/bench_observer.c, HONEST_SIXTH).

Made on 2026-11-27 at 13:42 UTC, after the fifth set had measured the method (and its frequency-
scaling option), and committed before the next change to the method was tried: nothing is tuned
on them, and they are run once, on the method as it is then left. None is of the parametric form
the bayes method and the QUEST+ anchor fit, and the shapes differ from all earlier sets.

observer_dog.csv -- a difference-of-Gaussians CSF in linear frequency (centre-surround receptive
  fields, in the manner of Wilson's and Enroth-Cugell & Robson's models):
  S0(f) = exp(-(f / 7)^2) - 0.8 exp(-(f / 1.1)^2), normalised to a peak of 260; the periphery
  is the same mechanism magnified, centre and surround scales / (1 + e / 6) and amplitude
  x (1 + e / 6)^-0.5.
observer_sampling.csv -- Barten's simplified CSF (1999) at 30 cd/m^2, 2 deg field; the periphery
  loses 0.008 log10 per degree at every frequency and is cut off smoothly at the resolution limit
  that ganglion-cell sampling sets (Thibos et al. 1987): S x exp(-(f / fc(e))^2),
  fc(e) = 30 / (1 + e / 2) cpd (the fovea's own cut-off is Barten's).
observer_fsq.csv -- a high-peaked narrow observer (log-parabola, peak 5 cpd, Smax 300, full
  bandwidth 2.2 octaves, low-frequency plateau 0.35 log10 under the peak) whose eccentricity loss
  grows with the square of frequency: log10 loss = 0.02 e + 0.0015 f^2 e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 202611276, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout6.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 202611276


def dog0(f):
    return math.exp(-(f / 7.0) ** 2) - 0.8 * math.exp(-(f / 1.1) ** 2)


DOG_PEAK = max(dog0(0.01 * k) for k in range(1, 3000))


def dog(f, e):
    m = 1.0 + e / 6.0
    return 260.0 * m ** -0.5 * max(dog0(f * m), 1e-9) / DOG_PEAK


def sampling(f, e):
    fc = 30.0 / (1.0 + e / 2.0)
    cut = math.exp(-(f / fc) ** 2) if e > 0 else 1.0
    return barten(f, 30.0) * 10 ** (-0.008 * e) * cut


def fsq(f, e):
    half = 2.2 * math.log10(2.0) / 2.0
    u = (math.log10(f) - math.log10(5.0)) / half
    ls = math.log10(300.0) - math.log10(2.0) * u * u
    if f < 5.0:
        ls = max(ls, math.log10(300.0) - 0.35)
    return 10 ** (ls - 0.02 * e - 0.0015 * f * f * e)


TRUTHS = (("dog", dog), ("sampling", sampling), ("fsq", fsq))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
