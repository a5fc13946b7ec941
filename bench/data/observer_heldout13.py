#!/usr/bin/env python3
"""Writes the THIRTEENTH held-out truths of bench_observer --honest --heldout 13, and
prints the observer specs the bench compiles in (bench/bench_observer.c, HONEST_THIRTEENTH).

Made on 2026-11-28 at 03:24 UTC, after the twelfth set had judged the decision-model mixture, and
before any later change to the method: nothing is tuned on them; they are to be run once, on the
method as the next change leaves it. None is of the parametric form the bayes method and the
QUEST+ anchor fit. The set holds one truth with a poor fovea (the failure sets 10 and 12 showed),
one with a poor mid-periphery and one of normal form but lower and shifted; they were chosen for
the spread of real observers, not for any option.

observer_child5.csv -- a five-year-old (after the reductions Ellemberg et al. 1999 report against
  adults): Barten's CSF at 50 cd/m^2, 10 deg field, less sensitive by log10 0.25 + 0.12 log2 f
  above 1 cpd (0.25 below); the periphery loses log10 0.012 (1 + f) e.
observer_rpring.csv -- early retinitis pigmentosa, a mid-peripheral ring scotoma with the centre
  spared: Barten at 100 cd/m^2, 10 deg field, the periphery after Pointer & Hess (1989),
  log10 0.01 f e + 0.01 e, and a ring losing log10 0.6 exp(-((e - 15) / 5)^2).
observer_csc.csv -- central serous chorioretinopathy, a foveal loss that grows with frequency:
  Barten at 30 cd/m^2, 4 deg field, the fovea less sensitive by log10 (0.15 + 0.1 log2(1 + f))
  exp(-(e / 3)^2); the periphery loses log10 0.015 f e + 0.005 e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026112813, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout13.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 2026112813


def child5(f, e):
    loss = 0.25 + 0.12 * max(0.0, math.log2(f)) + 0.012 * (1.0 + f) * e
    return barten(f, 50.0, 10.0) * 10 ** -loss


def rpring(f, e):
    loss = 0.01 * f * e + 0.01 * e + 0.6 * math.exp(-(((e - 15.0) / 5.0) ** 2))
    return barten(f, 100.0, 10.0) * 10 ** -loss


def csc(f, e):
    loss = (0.15 + 0.1 * math.log2(1.0 + f)) * math.exp(-((e / 3.0) ** 2)) + 0.015 * f * e + 0.005 * e
    return barten(f, 30.0, 4.0) * 10 ** -loss


TRUTHS = (("child5", child5), ("rpring", rpring), ("csc", csc))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
