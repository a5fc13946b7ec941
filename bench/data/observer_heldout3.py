#!/usr/bin/env python3
"""Writes the THIRD held-out truths of bench_observer --honest --heldout 3, and prints
the observer specs the bench compiles in (bench/bench_observer.c, HONEST_THIRD).

Made on 2026-11-27 at 10:15 UTC, at the start of that day's work on the bayes method and before
any of it: nothing is tuned on them, and they are run once, after the method is frozen. None is
of the parametric form the bayes method and the QUEST+ anchor fit (truncated log-parabola x
stelaCSF), and the shapes differ from the other held-out sets (observer_heldout.py,
observer_heldout2.py) and from the tuned-on ones (observer_bumpy.py, observer_mscaled.py).

observer_mansak.csv -- Mannos & Sakrison's (1974) foveal form A(f) = 2.6 (0.0192 + 0.114 f)
  exp(-(0.114 f)^1.1) (peak near 8 cpd), scaled to Smax 180; eccentricity as a pure frequency
  scaling with Rovamo & Virsu's (1979) temporal-field magnification M(e) = 1 / (1 + 0.29 e +
  0.000012 e^3) applied to frequency and, in part, to sensitivity: S(f, e) = M^0.7 S0(f / M)
  (flat across eccentricity at the lowest frequencies, as for fixed-size gratings).
observer_bartlow.csv -- an older observer: Barten's simplified CSF (1999) at 30 cd/m^2, 2 deg
  field, frequency axis x 0.75 (optics: the cut-off falls), sensitivity x 0.6; eccentricity as a
  band that narrows from the top: S(f, e) = S0(f) exp(-(f e / 18)^1.4) / (1 + e / 40).
observer_ridge.csv -- a low-pass-ish observer with a broad plateau: a difference of exponentials
  S0(f) = 220 (exp(-f / 9) - 0.85 exp(-f / 0.9)), eccentricity as a linear log10 loss with a
  frequency-dependent part that saturates: log10 S(f, e) = log10 S0(f) - 0.02 e - 0.06 e f / (1 + f / 6).
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: drawn here with random.Random(SEED), SEED = 20261127, the same scheme as
observer_heldout2.py: for each truth one Weibull and one signal-detection observer with slope
(Weibull) or 1.21 k (sdt) log-uniform in 2-5 and lapse uniform in 0-0.05, then one Weibull and
one sdt observer in the corners of the wide range (slope / 1.21 k log-uniform in 1.5-2 or 5-6,
lapse uniform 0.05-0.08) on the first two truths.
Run from bench/data: python3 observer_heldout3.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 20261127


def mansak0(f):
    return 2.6 * (0.0192 + 0.114 * f) * math.exp(-((0.114 * f) ** 1.1))


def mansak(f, e):
    m = 1.0 / (1.0 + 0.29 * e + 0.000012 * e ** 3)
    peak = max(mansak0(0.1 * k) for k in range(1, 300))
    return 180.0 * m ** 0.7 * mansak0(f / m) / peak


def bartlow(f, e):
    s0 = 0.6 * barten(f / 0.75, 30.0)
    return s0 * math.exp(-((f * e / 18.0) ** 1.4)) / (1.0 + e / 40.0)


def ridge(f, e):
    s0 = 220.0 * (math.exp(-f / 9.0) - 0.85 * math.exp(-f / 0.9))
    if s0 <= 0:
        return 0.0
    return s0 * 10 ** (-0.02 * e - 0.06 * e * f / (1.0 + f / 6.0))


TRUTHS = (("mansak", mansak), ("bartlow", bartlow), ("ridge", ridge))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
