#!/usr/bin/env python3
"""Writes the FIFTH held-out truths of bench_observer --honest --heldout 5, and prints
the observer specs the bench compiles in (bench/bench_observer.c, HONEST_FIFTH).

Made on 2026-11-27 at 12:55 UTC, at the start of a session that set out to change how the bayes
method treats the foveal row, and committed before any such change was tried: nothing is tuned on
them, and they are run once, on the method as it is finally left. None is of the parametric form
the bayes method and the QUEST+ anchor fit, and the shapes differ from all earlier sets.

observer_defocus.csv -- an uncorrected refractive error: Barten's simplified CSF (1999) at
  80 cd/m^2, 2 deg field, times the geometric-optics MTF of 0.5 D of defocus through a 4 mm pupil
  (blur circle 2 mrad = 0.115 deg; MTF = |2 J1(x) / x|, x = pi * 0.115 f, first zero near
  10.6 cpd), floored at 0.03 (aberrations and the ocular point spread keep the zero from being
  total); eccentricity as cortical magnification with Rovamo & Virsu's (1979) inferior field,
  M(e) = 1 / (1 + 0.42 e + 0.000055 e^3), applied to the neural CSF only, since the defocus is the
  same at every eccentricity: S(f, e) = MTF(f) M S0(f / M).
observer_ngan.csv -- Ngan, Leong & Singh's (1986) foveal CSF, S0(f) = (0.31 + 0.69 f) exp(-0.29 f)
  (peak at 3 cpd, a low-frequency plateau at 0.25 of the peak), scaled to Smax 220; an
  eccentricity loss that accelerates, log10 S(f, e) = log10 S0(f) - 0.018 f e - 0.0012 e^2.
observer_mkpower.csv -- Movshon & Kiorpes' (1988) form S0(f) = f^1.5 exp(-f / 2.2) (peak 3.3 cpd,
  a steep low-frequency fall-off), Smax 130; eccentricity as a power of eccentricity in periods,
  log10 S(f, e) = log10 S0(f) - 0.06 (f e)^0.75: concave in e, between the linear gradient of
  Pointer & Hess (1989) and cortical magnification.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 202611275, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout5.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 202611275
BLUR_DEG = 0.5 * 4e-3 * 180.0 / math.pi  # 0.5 D x 4 mm pupil, in degrees of visual angle


def bessel_j1(x):
    # power series; x stays below 40 on the written grid, where 60 terms converge in doubles
    term, total, k = x / 2.0, 0.0, 0
    while k < 60:
        total += term
        k += 1
        term *= -(x * x / 4.0) / (k * (k + 1))
    return total


def defocus_mtf(f):
    x = math.pi * BLUR_DEG * f
    if x < 1e-9:
        return 1.0
    if x > 30.0:  # asymptotic envelope beyond the series' comfortable range
        return max(0.03, 2.0 * math.sqrt(2.0 / (math.pi * x)) / x)
    return max(0.03, abs(2.0 * bessel_j1(x) / x))


def defocus(f, e):
    m = 1.0 / (1.0 + 0.42 * e + 0.000055 * e ** 3)
    return defocus_mtf(f) * m * barten(f / m, 80.0)


def ngan(f, e):
    def s0(u):
        return (0.31 + 0.69 * u) * math.exp(-0.29 * u)
    return 220.0 * s0(f) / s0(0.6001 / 0.2001) * 10 ** (-0.018 * f * e - 0.0012 * e * e)


def mkpower(f, e):
    def s0(u):
        return u ** 1.5 * math.exp(-u / 2.2)
    return 130.0 * s0(f) / s0(3.3) * 10 ** (-0.06 * (f * e) ** 0.75)


TRUTHS = (("defocus", defocus), ("ngan", ngan), ("mkpower", mkpower))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
