#!/usr/bin/env python3
"""Writes the EIGHTEENTH held-out truths of bench_observer --honest --heldout 18 (and bench_coverage,
bench_efficiency --sets 18), and prints the observer specs the bench compiles in
(bench/honest_sets.h, HONEST_EIGHTEENTH).

Made on 2026-11-29 at 16:20 UTC, after seventeen sets had been seen by the bayes method, for the
next change to it (kept unseen until that change is judged on it, and run once then). None is of
the parametric form the bayes method and the QUEST+ anchor fit. Chosen for shapes no earlier set
has: a loss in a parafoveal ring that spares the fovea and the far periphery, a person better than
the population almost everywhere, and a crossing loss (better at low frequencies, worse at high).

observer_bullseye.csv -- hydroxychloroquine (bull's-eye) maculopathy (after Marmor et al. 2016: the
  damage is a parafoveal ring, about 2-6 deg, with the fovea spared until late): Barten at
  100 cd/m^2, 10 deg field; the ring costs log10 0.5 exp(-((e - 4) / 2.5)^2) (1 + 0.2 max(0,
  log2(f / 2))); the periphery loses log10 0.012 f e + 0.01 e.
observer_supernorm.csv -- a young adult at a bright display (after Owsley et al. 1983's youngest
  group and Barten's luminance dependence: sensitivity above the population everywhere, and a
  shallow loss with eccentricity): Barten at 300 cd/m^2, 10 deg field, x 1.3; the periphery loses
  log10 0.008 f e + 0.006 e.
observer_mydriasis.csv -- a dilated 8 mm pupil (after Campbell & Green 1965 and Artal's aberration
  measurements: more retinal illuminance helps low frequencies, the larger aberrations cost high
  ones): Barten at 100 cd/m^2, 10 deg field, x 10^0.1; the optics cost log10 0.35 max(0, log2(f /
  3))^1.2 times exp(-e / 10); the periphery loses log10 0.013 f e + 0.012 e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026112918, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout18.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 2026112918


def bullseye(f, e):
    ring = 0.5 * math.exp(-(((e - 4.0) / 2.5) ** 2)) * (1.0 + 0.2 * max(0.0, math.log2(f / 2.0)))
    return barten(f, 100.0, 10.0) * 10 ** -(ring + 0.012 * f * e + 0.01 * e)


def supernorm(f, e):
    return 1.3 * barten(f, 300.0, 10.0) * 10 ** -(0.008 * f * e + 0.006 * e)


def mydriasis(f, e):
    optics = 0.35 * max(0.0, math.log2(f / 3.0)) ** 1.2 * math.exp(-e / 10.0)
    return 10 ** 0.1 * barten(f, 100.0, 10.0) * 10 ** -(optics + 0.013 * f * e + 0.012 * e)


TRUTHS = (("bullseye", bullseye), ("supernorm", supernorm), ("mydriasis", mydriasis))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
