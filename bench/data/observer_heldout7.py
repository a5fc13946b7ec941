#!/usr/bin/env python3
"""Writes the SEVENTH held-out truths of bench_observer --honest --heldout 7, and prints
the observer specs the bench compiles in (bench/bench_observer.c, HONEST_SEVENTH).

Made on 2026-11-27 at 15:00 UTC, at the start of a session, before the frequency-scaling option
was run on the sixth set and before any change to the method was tried: nothing is tuned on
them, and they are run once, on the method as it is finally left. None is of the parametric form
the bayes method and the QUEST+ anchor fit, and the shapes differ from all earlier sets.

observer_kelly.csv -- Kelly's (1979) spatio-temporal CSF at the slow retinal drift of steady
  fixation (v = 0.15 deg/s): S0(f) = k(v) v a^2 exp(-2 a (v + 2) / 45.9), a = 2 pi f,
  k(v) = 6.1 + 7.3 |log10(v / 3)|^3 (peak near 3.4 cpd, a steep low-frequency flank), scaled to
  Smax 200; eccentricity as Daly's (1993) pure frequency scaling S(f, e) = S0(f (1 + 0.24 e)),
  with no loss of peak sensitivity.
observer_amblyopic.csv -- an anisometropic amblyope's eye: Barten's simplified CSF (1999) at
  40 cd/m^2, 2 deg field, with a foveal high-frequency loss exp(-(f / fa(e))^2) that fades with
  eccentricity, fa(e) = 6 (1 + e / 4) cpd (the periphery of an amblyopic eye is near normal),
  on top of an ordinary log10 loss (0.01 + 0.012 f) e: the fovea-to-periphery fall-off at high
  frequencies is much flatter than in a normal eye.
observer_rodlow.csv -- a dim display (Barten at 2 cd/m^2, 10 deg field): the rod-rich near
  periphery is more sensitive than the fovea at low frequencies, log10 S(f, e) = log10 S0(f)
  + 0.2 (1 - exp(-e / 4)) exp(-f / 1.5) - 0.028 f e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 202611277, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout7.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 202611277


def kelly0(f):
    v = 0.15
    a = 2.0 * math.pi * f
    k = 6.1 + 7.3 * abs(math.log10(v / 3.0)) ** 3
    return k * v * a * a * math.exp(-2.0 * a * (v + 2.0) / 45.9)


KELLY_PEAK = max(kelly0(0.01 * k) for k in range(1, 3000))


def kelly(f, e):
    return 200.0 * kelly0(f * (1.0 + 0.24 * e)) / KELLY_PEAK


def amblyopic(f, e):
    fa = 6.0 * (1.0 + e / 4.0)
    return barten(f, 40.0) * math.exp(-(f / fa) ** 2) * 10 ** (-(0.01 + 0.012 * f) * e)


def rodlow(f, e):
    gain = 0.2 * (1.0 - math.exp(-e / 4.0)) * math.exp(-f / 1.5)
    return barten(f, 2.0, 10.0) * 10 ** (gain - 0.028 * f * e)


TRUTHS = (("kelly", kelly), ("amblyopic", amblyopic), ("rodlow", rodlow))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
