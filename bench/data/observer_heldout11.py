#!/usr/bin/env python3
"""Writes the ELEVENTH held-out truths of bench_observer --honest --heldout 11, and
prints the observer specs the bench compiles in (bench/bench_observer.c, HONEST_ELEVENTH).

Made on 2026-11-28 at 00:50 UTC, after the tenth set had measured the shipped method and judged
the decision-model option (not adopted), and before any later change to the method: nothing is
tuned on them; they are to be run once, on the method as the next change leaves it. None is of
the parametric form the bayes method and the QUEST+ anchor fit, and the shapes differ from every
earlier set.

observer_pyramid.csv -- Watson & Ahumada's (2016) "pyramid of visibility": above the peak, log10
  sensitivity falls linearly in frequency (not in log frequency), here 2.45 - 0.062 f, and
  linearly in eccentricity with a frequency-dependent rate, - (0.012 + 0.0045 f) e; below the
  peak a roll-off 1 / (1 + (0.9 / f)^1.6).
observer_aged.csv -- an older observer (after Owsley, Sekuler & Siemsen 1983): Barten's
  simplified CSF at 30 cd/m^2 (smaller pupil, less retinal light), 4 deg field, a further
  optical and neural high-frequency loss 0.35 (f / 8)^1.3 log10, and a peripheral loss that grows
  with age faster at high frequencies, log10 (0.018 + 0.0035 f) e + 0.0006 e^2.
observer_adapted.csv -- an observer adapted to a 4 cpd grating (Blakemore & Campbell 1969): Barten
  at 100 cd/m^2, 10 deg field, with a notch of 0.3 log10 centred on 4 cpd, 0.7 octaves wide (sd),
  at every eccentricity; the periphery loses 0.016 f^0.8 e + 0.006 e log10.
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: random.Random(SEED), SEED = 2026112811, the scheme of observer_heldout2.py
(two narrow observers per truth, Weibull and sdt, then the wide-range corners on the first two).
Run from bench/data: python3 observer_heldout11.py"""
import math

from observer_heldout2 import barten, specs, write_tables

SEED = 2026112811


def pyramid(f, e):
    log_s = 2.45 - 0.062 * f - (0.012 + 0.0045 * f) * e
    return 10 ** log_s / (1.0 + (0.9 / f) ** 1.6)


def aged(f, e):
    loss = 0.35 * (f / 8.0) ** 1.3 + (0.018 + 0.0035 * f) * e + 0.0006 * e * e
    return barten(f, 30.0, 4.0) * 10 ** -loss


def adapted(f, e):
    notch = 0.3 * math.exp(-0.5 * (math.log2(f / 4.0) / 0.7) ** 2)
    return barten(f, 100.0, 10.0) * 10 ** -(notch + 0.016 * f ** 0.8 * e + 0.006 * e)


TRUTHS = (("pyramid", pyramid), ("aged", aged), ("adapted", adapted))


if __name__ == "__main__":
    write_tables(TRUTHS)
    for line in specs(SEED, TRUTHS):
        print("    " + line)
