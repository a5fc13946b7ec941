#!/usr/bin/env python3
"""Writes the TWELFTH held-out truths of bench_observer --honest --heldout 12, and
prints the observer specs the bench compiles in (bench/bench_observer.c, HONEST_TWELFTH).

Made on 2026-11-28 at 02:15 UTC, after the eleventh set had judged the decision-model mixture
with a 0.2 prior on high threshold (it passed there; a failing test then kept it off), and
before any later change to the method: nothing
is tuned on them; they are to be run once, on the method as the next change leaves it. None is of
the parametric form the bayes method and the QUEST+ anchor fit, and the shapes differ from every
earlier set.

observer_defocus1d.csv -- Barten's simplified CSF (1999) at 100 cd/m^2, 10 deg field, through
  1 D of uncorrected defocus at a 3 mm pupil: the geometric-optics MTF 2 J1(x) / x with
  x = pi * 0.172 deg * f (first zero near 7.1 cpd; the side lobes give spurious resolution above
  it), its modulus floored at 0.02 for the aberrations that fill the zero; the periphery loses
  log10 0.025 (1 + f / 5) e.
observer_scotopic.csv -- a dark-adapted, rod-mediated observer: Barten at 0.1 cd/m^2 (peak near
  1 cpd, steep above), the rod-free fovea 0.4 log10 less sensitive within about 1.5 deg, and a
  periphery that loses log10 0.02 f e + 0.004 e.
observer_asym.csv -- an asymmetric log-parabola (Chung & Legge 2016 style): peak 180 at 3.5 cpd,
  half height 2.2 octaves below the peak and 1.4 octaves above it; the periphery after Pointer &
  Hess (1989), log10 0.008 f^1.2 e + 0.01 e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026112812, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout12.py"""
import math

from observer_heldout2 import barten, specs, write_tables
from observer_heldout5 import bessel_j1

SEED = 2026112812


def defocus1d(f, e):
    x = math.pi * 0.172 * f
    mtf = max(0.02, abs(2.0 * bessel_j1(x) / x))
    return barten(f, 100.0, 10.0) * mtf * 10 ** (-0.025 * (1.0 + f / 5.0) * e)


def scotopic(f, e):
    loss = 0.4 * math.exp(-((e / 1.5) ** 2)) + 0.02 * f * e + 0.004 * e
    return barten(f, 0.1, 10.0) * 10 ** -loss


def asym(f, e):
    half = 2.2 if f < 3.5 else 1.4
    u = math.log2(f / 3.5) / half
    return 180.0 * 10 ** (-math.log10(2.0) * u * u - 0.008 * f ** 1.2 * e - 0.01 * e)


TRUTHS = (("defocus1d", defocus1d), ("scotopic", scotopic), ("asym", asym))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
