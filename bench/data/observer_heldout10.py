#!/usr/bin/env python3
"""Writes the TENTH held-out truths of bench_observer --honest --heldout 10, and prints
the observer specs the bench compiles in (bench/bench_observer.c, HONEST_TENTH).

Made on 2026-11-27 at 20:20 UTC, after the ninth set had measured the shipped method (the two
options screened that evening were not adopted) and before any later change to the method:
nothing is tuned on them; they are to be run once, on the method as the next change leaves it.
None is of the parametric form the bayes method and the QUEST+ anchor fit, and the shapes differ
from every earlier set.

observer_macular.csv -- Barten's simplified CSF (1999) at 100 cd/m^2, 4 deg field, with an
  ordinary peripheral loss, log10 0.02 (1 + f / 4) e, and the central depression of early
  macular degeneration: a further 0.5 exp(-(e / 3)^2) (0.6 + f / 10) log10, largest at high
  frequencies and gone by 5 deg, so the fovea sits below the 5 deg ring.
observer_kellymotion.csv -- Kelly's (1979) spatio-temporal CSF with Daly's (1998) constants
  (s1 6.1, s2 7.3, p1 45.9, c0 1.14, c1 0.67, c2 1.7) at a retinal velocity of 2 deg/s, an eye
  whose fixation is unsteady: peak about 230 near 2 cpd and a steep cut-off above it; the
  periphery loses super-linearly in cycles of eccentricity, log10 0.012 (f e)^1.15 + 0.01 e.
observer_cataract.csv -- Barten's simplified CSF at 200 cd/m^2, 10 deg field, seen through an
  early cataract: veiling light from straylight equal to 0.4 of the background cuts every
  contrast by 1 / 1.4, and the scattered wavefront is an MTF exp(-(f / 9)^2); the periphery loses
  in proportion to the square root of frequency, log10 0.03 sqrt(f) e.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026112710, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout10.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 2026112710


def macular(f, e):
    loss = 0.02 * (1.0 + f / 4.0) * e + 0.5 * math.exp(-((e / 3.0) ** 2)) * (0.6 + f / 10.0)
    return barten(f, 100.0, 4.0) * 10 ** -loss


def kelly(rho, v):
    s1, s2, p1, c0, c1, c2 = 6.1, 7.3, 45.9, 1.14, 0.67, 1.7
    k = s1 + s2 * abs(math.log10(c2 * v / 3.0)) ** 3
    rho_max = p1 / (c2 * v + 2.0)
    return k * c0 * c2 * v * (c1 * 2.0 * math.pi * rho) ** 2 * math.exp(-c1 * 4.0 * math.pi * rho / rho_max)


def kellymotion(f, e):
    return kelly(f, 2.0) * 10 ** (-0.012 * (f * e) ** 1.15 - 0.01 * e)


def cataract(f, e):
    return barten(f, 200.0, 10.0) / 1.4 * math.exp(-((f / 9.0) ** 2)) * 10 ** (-0.03 * math.sqrt(f) * e)


TRUTHS = (("macular", macular), ("kellymotion", kellymotion), ("cataract", cataract))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
