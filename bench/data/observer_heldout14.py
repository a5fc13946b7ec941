#!/usr/bin/env python3
"""Writes the FOURTEENTH held-out truths of bench_observer --honest --heldout 14, and
prints the observer specs the bench compiles in (bench/bench_observer.c, HONEST_FOURTEENTH).

Made on 2026-11-28 at 05:29 UTC, after the thirteenth set had judged the two-sided foveal term,
and before any later change to the method: nothing is tuned on them; they are to be run once, on
the method as the next change leaves it. None is of the parametric form the bayes method and the
QUEST+ anchor fit. They were chosen for the spread of real observers: a loss confined to middle
frequencies, a periphery that falls faster than normal, and a fovea no better than its surround.

observer_optneur.csv -- recovered optic neuritis (after Regan, Silver & Murray 1977 and Zimmern,
  Campbell & Wilkinson 1979): Barten's CSF at 100 cd/m^2, 10 deg field, a selective loss of
  log10 0.35 exp(-(log2(f / 5) / 0.8)^2) that is strongest centrally (x (0.4 + 0.6 exp(-(e / 8)^2)));
  the periphery loses log10 0.01 f e + 0.01 e.
observer_myope6.csv -- a corrected high myope (-6 D; after Liou & Chiu 2001 centrally and Chui,
  Yap, Chan & Thibos 2005 in the periphery): Barten at 100 cd/m^2, 10 deg field, less sensitive
  by log10 0.08 log2(1 + f) (spectacle minification, a stretched retina), and a periphery that
  falls faster than an emmetrope's: log10 0.018 f e + 0.006 e.
observer_albino.csv -- ocular albinism (foveal hypoplasia and nystagmus): the fovea is no better
  than the retina at 4 deg, e' = max(e, 4): Barten at 100 cd/m^2, 10 deg field, losing
  log10 0.012 f e' + 0.005 e' + 0.002 f^2 (the smear of the eye's drift, worst at high frequency).
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026112814, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout14.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 2026112814


def optneur(f, e):
    notch = 0.35 * math.exp(-((math.log2(f / 5.0) / 0.8) ** 2)) * (0.4 + 0.6 * math.exp(-((e / 8.0) ** 2)))
    return barten(f, 100.0, 10.0) * 10 ** -(notch + 0.01 * f * e + 0.01 * e)


def myope6(f, e):
    loss = 0.08 * math.log2(1.0 + f) + 0.018 * f * e + 0.006 * e
    return barten(f, 100.0, 10.0) * 10 ** -loss


def albino(f, e):
    ee = max(e, 4.0)
    loss = 0.012 * f * ee + 0.005 * ee + 0.002 * f * f
    return barten(f, 100.0, 10.0) * 10 ** -loss


TRUTHS = (("optneur", optneur), ("myope6", myope6), ("albino", albino))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
