#!/usr/bin/env python3
"""Writes the NINETEENTH held-out truths of bench_observer --honest --heldout 19 (and bench_coverage,
bench_efficiency --sets 19), and prints the observer specs the bench compiles in
(bench/honest_sets.h, HONEST_NINETEENTH).

Made on 2026-11-30 at 14:45 UTC, after eighteen sets had been seen by the bayes method, for the
next change to it (kept unseen until that change is judged on it, and run once then). None is of
the parametric form the bayes method and the QUEST+ anchor fit. Chosen for shapes no earlier set
has: a field that ends at the edge of a tunnel (a cliff in eccentricity at every frequency, where
the earlier rings recover outside them), a periphery that still detects fine gratings beyond its
resolution limit (a shallow high-frequency tail where a loss linear in f e says never visible),
and a loss at low frequencies that grows with eccentricity.

observer_rptunnel.csv -- retinitis pigmentosa with tunnel vision (after Berson 1993: the field
  closes in from the mid-periphery to a central island; Alexander et al. 2004: the island's own
  contrast sensitivity loses most at the highest frequencies): Barten at 100 cd/m^2, 10 deg field;
  the island's edge costs log10 1.6 / (1 + exp(-(e - 11) / 1.8)) at every frequency (half of it at
  11 deg, near the 20 deg diameter of legal blindness, nine tenths of it at 15 deg); the centre
  loses log10 0.08 + 0.12 max(0, log2(f / 2)); the periphery loses log10 0.012 f e + 0.01 e.
observer_alias.csv -- a young adult whose peripheral optics pass gratings finer than the retina
  resolves (after Thibos, Still & Bradley 1996 and Anderson, Evans & Thibos 1996: in the periphery
  a grating beyond the resolution limit is still detected, as an aliased pattern, and the detection
  CSF runs smoothly through that limit, where sensitivity is still about 10, to a detection limit
  several times higher): Barten at 100 cd/m^2, 10 deg field, the periphery losing log10
  0.012 f e + 0.01 e, pooled (fourth-power Minkowski sum, probability summation) with an aliasing
  route S_a = 10 (f / fr)^-1.25 (1 - exp(-e / 3)) above the resolution limit fr(e) = 30 / (1 + e /
  3.5) cpd (3.1 cpd at 30 deg, and a detection limit near 20 cpd there) and nothing below it; the
  fovea's cones out-sample its optics, so it has no aliasing zone.
observer_csnb.csv -- complete congenital stationary night blindness at a dim display (after Miyake
  et al. 1986: no rod function and a mildly reduced photopic acuity; at mesopic levels the rods'
  share of sensitivity is largest at low frequencies away from the rod-free fovea, Zele & Cao
  2015): Barten at 1 cd/m^2, 10 deg field; the missing rods cost log10 0.35 (1 - exp(-e / 4)) /
  (1 + (f / 1.5)^2); the cone pathway loses log10 0.1 + 0.2 max(0, log2(f / 4)) at every
  eccentricity; the periphery loses log10 0.012 f e + 0.01 e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026113019, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout19.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 2026113019


def rptunnel(f, e):
    centre = 0.08 + 0.12 * max(0.0, math.log2(f / 2.0))
    tunnel = 1.6 / (1.0 + math.exp(-(e - 11.0) / 1.8))
    return barten(f, 100.0, 10.0) * 10 ** -(centre + tunnel + 0.012 * f * e + 0.01 * e)


def alias(f, e):
    resolved = barten(f, 100.0, 10.0) * 10 ** -(0.012 * f * e + 0.01 * e)
    fr = 30.0 / (1.0 + e / 3.5)
    aliased = 10.0 * (f / fr) ** -1.25 * (1.0 - math.exp(-e / 3.0)) if f > fr else 0.0
    return (resolved ** 4 + aliased ** 4) ** 0.25


def csnb(f, e):
    rods = 0.35 * (1.0 - math.exp(-e / 4.0)) / (1.0 + (f / 1.5) ** 2)
    cones = 0.1 + 0.2 * max(0.0, math.log2(f / 4.0))
    return barten(f, 1.0, 10.0) * 10 ** -(rods + cones + 0.012 * f * e + 0.01 * e)


TRUTHS = (("rptunnel", rptunnel), ("alias", alias), ("csnb", csnb))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
