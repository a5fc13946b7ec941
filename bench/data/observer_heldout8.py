#!/usr/bin/env python3
"""Writes the EIGHTH held-out truths of bench_observer --honest --heldout 8, and prints
the observer specs the bench compiles in (bench/bench_observer.c, HONEST_EIGHTH).

Made on 2026-11-27 at 16:20 UTC, after the seventh set had measured the method with its frequency
scaling switched on, and committed for the next change to the method: nothing is tuned on them,
and they are to be run once, on the method as it is left after that change. None is of the
parametric form the bayes method and the QUEST+ anchor fit, and the shapes differ from all
earlier sets.

observer_modelfest.csv -- the ModelFest standard foveal CSF (Watson & Ahumada 2005, the
  hyperbolic-secant difference S0(f) = g (sech((f / 4.3469)^0.7929) - 0.8514 sech(f / 1.4476)),
  g = 373.08); the periphery as retinal sampling: Watson's (2014) midget ganglion-cell density
  along the temporal meridian, d(e) / d(0) = (0.9851 (1 + e / 1.058)^-2 + 0.0149 exp(-e / 22.14))
  / (1 + e / 41.03), sets a Nyquist cut-off 55 sqrt(d(e) / d(0)) cpd, S(f, e) =
  S0(f) (d(e) / d(0))^0.15 exp(-(f / fc(e))^2) (the fovea keeps its own cut-off).
observer_periphdefocus.csv -- Barten's simplified CSF (1999) at 60 cd/m^2, 2 deg field, seen
  through the relative peripheral hyperopia of a myope: 0.03 D per degree of eccentricity
  through a 5 mm pupil (blur circle 0.03 e * 5 mm rad / 1000 -> degrees), geometric-optics MTF
  |2 J1(x) / x| floored at 0.05, on top of a small neural loss 0.012 f e log10.
observer_lowpass.csv -- a low-pass observer, shaped like Mullen's (1985) isoluminant red-green
  CSF scaled to luminance sensitivities: S0(f) = 150 / (1 + (f / 1.2)^2.2) (flat below 0.5 cpd,
  no low-frequency fall-off at all), with the steeper eccentricity loss of the chromatic
  pathways (Mullen, Sakurai & Chu 2005): log10 loss 0.045 e + 0.01 f e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 202611278, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout8.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 202611278


def sech(x):
    return 2.0 / (math.exp(x) + math.exp(-x)) if x < 300 else 0.0


def modelfest0(f):
    return 373.08 * (sech((f / 4.3469) ** 0.7929) - 0.8514 * sech(f / 1.4476))


def rgc_density_ratio(e):
    return (0.9851 * (1.0 + e / 1.058) ** -2 + 0.0149 * math.exp(-e / 22.14)) / (1.0 + e / 41.03)


def modelfest(f, e):
    s0 = max(modelfest0(f), 1e-9)
    if e == 0:
        return s0
    d = rgc_density_ratio(e)
    fc = 55.0 * math.sqrt(d)
    return s0 * d ** 0.15 * math.exp(-(f / fc) ** 2)


def bessel_j1(x):
    # series for small x, asymptotic form for large x (enough for an MTF to 1e-4)
    if x < 8.0:
        term, s, k = x / 2.0, 0.0, 0
        while abs(term) > 1e-12 and k < 60:
            s += term
            k += 1
            term *= -(x * x / 4.0) / (k * (k + 1))
        return s
    return math.sqrt(2.0 / (math.pi * x)) * math.cos(x - 0.75 * math.pi)


def periphdefocus(f, e):
    blur_deg = math.degrees(0.03 * e * 5.0 / 1000.0)
    x = math.pi * blur_deg * f
    mtf = 1.0 if x < 1e-9 else abs(2.0 * bessel_j1(x) / x)
    return barten(f, 60.0) * max(mtf, 0.05) * 10 ** (-0.012 * f * e)


def lowpass(f, e):
    return 150.0 / (1.0 + (f / 1.2) ** 2.2) * 10 ** (-(0.045 + 0.01 * f) * e)


TRUTHS = (("modelfest", modelfest), ("periphdefocus", periphdefocus), ("lowpass", lowpass))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
