#!/usr/bin/env python3
"""Writes the three HELD-OUT truths of bench_observer --honest. They were made
for the benchmark on 2026-11-23 and were not used to tune any method; none is of the parametric
form the bayes method and the QUEST+ anchor fit (truncated log-parabola x stelaCSF).

observer_msdexp.csv -- Mannos & Sakrison (1974) double-exponential form,
    A(u) = 2.6 (0.0192 + 0.114 u) exp(-(0.114 u)^1.1),   peak at u = 8 cpd,
  moved to a peak at 4 cpd (u = 2 f) and scaled to Smax 200; eccentricity with the NASAL-field
  stelaCSF constants (Mantiuk et al. 2022; a = 0.0114, b = 0.0194), i.e. a slower fall-off than the
  temporal field that the methods' priors centre on.
observer_older.csv -- an older / mildly low-vision observer: Barten's simplified CSF (Barten
  1999, eq. 3.26) at 10 cd/m^2 for a 2-deg field, frequency axis compressed by 0.6 (peak near
  2 cpd) and sensitivity scaled by 0.35 (Smax about 60); eccentricity as cortical magnification
  M(e) = 1 / (1 + 0.45 e) (steeper than Rovamo-Virsu's temporal field), S(f, e) = M S0(f / M).
observer_dexp.csv -- a difference of exponentials (band-pass DoE),
    S0(f) = K (exp(-f / 5.5) - exp(-f / 0.9)),  K such that Smax = 350 (peak near 2.2 cpd),
  broad at high frequency; temporal stelaCSF constants times an extra loss growing with e^2,
  10^(-(0.0297 + 0.019 f) e - 0.0006 e^2): the fall-off is not linear in e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).
Run from bench/data: python3 observer_heldout.py"""
import math

ECCS = [0, 2.5, 5, 7.5, 10, 15, 20, 30]
FREQS = [0.25 * 2 ** (k / 2) for k in range(13)]


def ms(u):
    return 2.6 * (0.0192 + 0.114 * u) * math.exp(-(0.114 * u) ** 1.1)


def msdexp(f, e):
    peak = max(ms(0.01 * i) for i in range(1, 4000))
    s0 = 200.0 * ms(2.0 * f) / peak
    return s0 * 10 ** (-(0.0114 + 0.0194 * f) * e)


def barten(u, lum, field=2.0):
    a = 540.0 * (1.0 + 0.7 / lum) ** -0.2 / (1.0 + 12.0 / (field * (1.0 + u / 3.0) ** 2))
    b = 0.3 * (1.0 + 100.0 / lum) ** 0.15
    return a * u * math.exp(-b * u) * math.sqrt(1.0 + 0.06 * math.exp(b * u))


def older(f, e):
    m = 1.0 / (1.0 + 0.45 * e)
    return 0.35 * m * barten(f / m / 0.6, 10.0)


def doe(f):
    return math.exp(-f / 5.5) - math.exp(-f / 0.9)


def dexp(f, e):
    peak = max(doe(0.01 * i) for i in range(1, 4000))
    return 350.0 * doe(f) / peak * 10 ** (-(0.0297 + 0.019 * f) * e - 0.0006 * e * e)


for name, fn in (("observer_msdexp.csv", msdexp), ("observer_older.csv", older),
                 ("observer_dexp.csv", dexp)):
    with open(name, "w") as out:
        out.write("freq_cpd,ecc_deg,threshold\n")
        for e in ECCS:
            for f in FREQS:
                s = fn(f, e)
                out.write("%.6g,%g,%.6g\n" % (f, e, min(1e6, 1.0 / s) if s > 0 else 1e6))
