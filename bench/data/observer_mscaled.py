#!/usr/bin/env python3
"""Writes observer_mscaled.csv: a smooth, realistic table-defined observer that is NOT of the
parametric form the bayes method fits (truncated log-parabola x stelaCSF, whose eccentricity loss
is linear in f*e).

Fovea: Barten's simplified CSF (Barten 1999, "Contrast sensitivity of the human eye and its
effects on image quality", eq. 3.26):
    S0(u) = a u exp(-b u) sqrt(1 + c exp(b u)),
    a = 540 (1 + 0.7/L)^-0.2 / (1 + 12 / (w (1 + u/3)^2)),  b = 0.3 (1 + 100/L)^0.15,  c = 0.06,
with L = 100 cd/m^2 and a field of w = 2 deg (a Gabor of sigma about 1 deg). Peak about 300 at
4-5 cpd; a gamma-like curve, steeper on the high side than the log-parabola.

Eccentricity: cortical magnification, temporal field (Rovamo & Virsu 1979),
    M(e) = 1 / (1 + 0.29 e + 0.000012 e^3),
scales frequency (a grating at e behaves like one at f / M(e) in the fovea) and, because the
stimulus keeps its size in degrees, it covers M(e)^2 of the cortical area an M-scaled stimulus
would; with sensitivity growing as the square root of the (cortical) area under spatial
summation, sensitivity scales by M(e):
    S(f, e) = M(e) * S0(f / M(e)).
The loss over eccentricity is therefore concave in e and steep at high frequency, not linear.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson)."""
import math


def magnification(e):
    return 1.0 / (1.0 + 0.29 * e + 0.000012 * e ** 3)


def barten(u, lum=100.0, field=2.0):
    a = 540.0 * (1.0 + 0.7 / lum) ** -0.2 / (1.0 + 12.0 / (field * (1.0 + u / 3.0) ** 2))
    b = 0.3 * (1.0 + 100.0 / lum) ** 0.15
    c = 0.06
    return a * u * math.exp(-b * u) * math.sqrt(1.0 + c * math.exp(b * u))


def sensitivity(f, e):
    m = magnification(e)
    return m * barten(f / m)


with open("observer_mscaled.csv", "w") as out:
    out.write("freq_cpd,ecc_deg,threshold\n")
    for e in [0, 2.5, 5, 7.5, 10, 15, 20, 30]:
        for k in range(13):
            f = 0.25 * 2 ** (k / 2)
            s = sensitivity(f, e)
            # far beyond visibility: keep the number finite (it is a threshold >= 1 either way)
            out.write("%.6g,%g,%.6g\n" % (f, e, min(1e6, 1.0 / s) if s > 0 else 1e6))
