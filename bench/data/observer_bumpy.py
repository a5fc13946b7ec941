#!/usr/bin/env python3
"""Writes observer_bumpy.csv: a table-defined observer whose surface is NOT of the parametric form
the bayes method fits (truncated log-parabola x stelaCSF). Foveal shape: a gamma-like curve
S0(f) = 320 f^0.7 exp(-0.32 f) with a 0.2 log10 notch near 4 cpd; eccentricity scales frequency
by (1 + 0.07 e) and adds a 0.015 log10/deg loss and a +-0.08 log10 ripple over eccentricity.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson)."""
import math

def log10_sensitivity(f, e):
    f2 = f * (1 + 0.07 * e)
    s0 = 320 * f2 ** 0.7 * math.exp(-0.32 * f2)
    notch = -0.2 * math.exp(-((math.log2(f) - 2) / 0.6) ** 2)
    ripple = 0.08 * math.sin(math.pi * e / 10) * math.cos(math.log2(f))
    return math.log10(s0) - 0.015 * e + notch + ripple

with open("observer_bumpy.csv", "w") as out:
    out.write("freq_cpd,ecc_deg,threshold\n")
    for e in [0, 2.5, 5, 7.5, 10, 15, 20, 30]:
        for k in range(11):
            f = 0.5 * 2 ** (k / 2)
            out.write("%.6g,%g,%.6g\n" % (f, e, 10 ** -log10_sensitivity(f, e)))
