#!/usr/bin/env python3
"""Writes the FRESH held-out truths of bench_observer --honest --fresh, and prints the
observer specs the bench compiles in (bench/bench_observer.c, HONEST_FRESH).

Made on 2026-11-23 at 22:35 UTC, after the bayes method was frozen for the final measurement of
that day, and never used for any tuning or development: nothing was run on them before the final
table. None is of the parametric form the bayes method and the QUEST+ anchor fit (truncated
log-parabola x stelaCSF), and the shapes differ from the first held-out set
(observer_heldout.py) and from the tuned-on ones (observer_bumpy.py, observer_mscaled.py).

observer_mkgp.csv -- Movshon & Kiorpes (1988) foveal form S0(f) = a f^c exp(-b f) with c = 1,
  b = 1/3 (peak at f = c/b = 3 cpd), scaled to Smax 150; eccentricity after Geisler & Perry
  (1998): contrast threshold CT(f, e) = CT(f, 0) exp(alpha f e / e2), alpha = 0.106, e2 = 2.3 deg,
  i.e. a loss proportional to f * e with no frequency-independent part.
observer_robson.csv -- a young observer at high luminance: Barten's simplified CSF (1999, eq.
  3.26) at 100 cd/m^2, 2 deg field, frequency axis x 1.2 (peak near 5 cpd), sensitivity x 0.9;
  eccentricity after Robson & Graham (1981): about 0.5 log10 per 10 periods of eccentricity, i.e.
  log10 S(f, e) = log10 S0(f) - 0.05 f e - 0.01 e.
observer_mesopic.csv -- a mesopic, low-pass-ish observer: Barten at 1 cd/m^2 (peak near 1.5 cpd,
  Smax about 45 after a x 0.8 scale), eccentricity as cortical magnification with Rovamo & Virsu's
  (1979) nasal field M(e) = 1 / (1 + 0.33 e + 0.00007 e^3), S(f, e) = M S0(f / M).
Thresholds >= 1 mean never visible. Columns: freq_cpd,ecc_deg,threshold (Michelson).

Psychometric functions: drawn here with random.Random(SEED), SEED = 20261123, in this order
(so the draw is reproducible): for each truth, one Weibull and one signal-detection observer
with slope (Weibull) or 1.21 k (sdt, the Weibull slope that fits its two-interval function)
log-uniform in 2-5 and lapse uniform in 0-0.05 (the <= 0.10 target's range), then one Weibull
and one sdt observer in the corners of the wide range that the narrow one leaves out (slope /
1.21 k log-uniform in 1.5-2 or 5-6, each side with probability 1/2; lapse uniform 0.05-0.08) on
the first two truths.
Run from bench/data: python3 observer_heldout2.py"""
import math
import random

SEED = 20261123
ECCS = [0, 2.5, 5, 7.5, 10, 15, 20, 30]
FREQS = [0.25 * 2 ** (k / 2) for k in range(13)]


def barten(u, lum, field=2.0):
    a = 540.0 * (1.0 + 0.7 / lum) ** -0.2 / (1.0 + 12.0 / (field * (1.0 + u / 3.0) ** 2))
    b = 0.3 * (1.0 + 100.0 / lum) ** 0.15
    return a * u * math.exp(-b * u) * math.sqrt(1.0 + 0.06 * math.exp(b * u))


def mk(f):
    return f * math.exp(-f / 3.0)


def mkgp(f, e):
    s0 = 150.0 * mk(f) / mk(3.0)
    return s0 * math.exp(-0.106 * f * e / 2.3)


def robson(f, e):
    s0 = 0.9 * barten(f / 1.2, 100.0)
    return s0 * 10 ** (-0.05 * f * e - 0.01 * e)


def mesopic(f, e):
    m = 1.0 / (1.0 + 0.33 * e + 0.00007 * e ** 3)
    return 0.8 * m * barten(f / m, 1.0)


TRUTHS = (("mkgp", mkgp), ("robson", robson), ("mesopic", mesopic))


def write_tables(truths=TRUTHS):
    for name, fn in truths:
        with open("observer_%s.csv" % name, "w") as out:
            out.write("freq_cpd,ecc_deg,threshold\n")
            for e in ECCS:
                for f in FREQS:
                    s = fn(f, e)
                    out.write("%.6g,%g,%.6g\n" % (f, e, min(1e6, 1.0 / s) if s > 0 else 1e6))


def log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def spec(rng, truth, decision, wide):
    if wide:  # outside the narrow range: slope 1.5-2 or 5-6, lapse 0.05-0.08
        s = log_uniform(rng, 1.5, 2.0) if rng.random() < 0.5 else log_uniform(rng, 5.0, 6.0)
        lapse = rng.uniform(0.05, 0.08)
    else:
        s = log_uniform(rng, 2.0, 5.0)
        lapse = rng.uniform(0.0, 0.05)
    narrow = int(2.0 <= s <= 5.0 and lapse <= 0.05)  # inside the <= 0.10 target range
    path = "bench/data/observer_%s.csv" % truth
    if decision == "sdt":
        k = s / 1.21
        return ('{"%s, sdt k %.2f/%.3f", "sim:decision=sdt,k=%.3f,lapse=%.3f,table=%s", 1, %d},'
                % (truth, k, lapse, k, lapse, path, narrow))
    return ('{"%s, Weibull %.2f/%.3f", "sim:slope=%.3f,lapse=%.3f,table=%s", 1, %d},'
            % (truth, s, lapse, s, lapse, path, narrow))


def specs(seed=SEED, truths=TRUTHS):
    """Two narrow observers per truth, then the wide-range corners on the first two (the draw
    order is part of each set's definition: the later sets reuse it with their own seed)."""
    rng = random.Random(seed)
    out = []
    for truth, _ in truths:
        for decision in ("weibull", "sdt"):
            out.append(spec(rng, truth, decision, False))
    for truth, _ in truths[:2]:
        for decision in ("weibull", "sdt"):
            out.append(spec(rng, truth, decision, True))
    return out


if __name__ == "__main__":
    write_tables()
    for line in specs():
        print("    " + line)
