#!/usr/bin/env python3
"""Writes the held-out observers of bench_velocity (observer_v_*.csv, columns
freq_cpd,ecc_deg,velocity_dps,threshold) and prints the observer specs the bench compiles in
(bench/bench_velocity.c, VEL_OBSERVERS).

Each person = a STATIC held-out person of bench/data (observer_<static>.csv, 13 frequencies
0.25-16 cpd x 8 eccentricities 0-30 deg) times a MOTION SHAPE: a log10 ratio of drifting to static
sensitivity R(f, tf) at spatial frequency f and temporal frequency tf = f v, tabulated at a few
nodes from published measurements (see README.md in this folder for where each node comes from and
how precise it is), then varied per person by four documented knobs. Nothing here is the
Kelly (1979) / Daly (1998) formula of model/csf_velocity.h, the prior the method starts from.

    log10 S(f, e, v) = log10 S_static(f, e) + R_person(f, e, f v)
    R_person(f, e, tf) = gain * max(R0, 0) + fall * min(R0, 0),
    R0 = R_shape(f, tf / (tf_scale * (1 + ecc_k * e)))

R_shape is interpolated linearly in (log2 f, log2 tf) between its nodes, held at its end rows in
frequency, 0 below the lowest temporal node (a grating at fixational drift is the static one) and
extrapolated along the last segment above the highest. tf_scale moves the whole temporal tuning
(lower retinal illuminance and age slow it); ecc_k moves it towards higher temporal frequencies
away from the fovea (the relative peripheral advantage at high temporal frequency); gain and fall
scale the rise and the fall.

Run from bench/data/velocity: python3 make_velocity.py"""
import math
import random

SEED = 2026112816
VELS = (0.0, 1.0, 2.0, 4.0, 8.0, 12.0, 16.0)
TF_NODES = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0)

# Robson (1966), Fig. 2: temporal contrast sensitivity of flickering gratings at 0.5, 4 and 16
# c/deg (20 cd/m^2, 2.5 x 2.5 deg field), as log10 ratios to the slowest modulation. Values
# read approximately from the published curves' shapes (not digitised; about +-0.1 log10 up to
# 16 Hz). The 32 and 64 Hz columns are set by where the curves end: gratings at this luminance
# stop being seen near 40-50 Hz (+-0.3 log10 at 32 Hz; 64 Hz only carries the fall past it).
ROBSON66 = {
    0.5: (0.0, 0.10, 0.22, 0.35, 0.42, 0.25, -0.60, -2.50),
    4.0: (0.0, 0.03, 0.06, 0.08, 0.02, -0.30, -1.30, -3.00),
    16.0: (0.0, -0.02, -0.08, -0.20, -0.45, -0.90, -1.80, -3.00),
}
# Drifting gratings: every spatial frequency's sensitivity peaks at the same temporal frequency,
# about 6 Hz (Tolhurst, Sharpe & Hart 1973), and motion raises sensitivity most, by up to 0.3
# log10, around 2-3 c/deg (Tulunay-Keesey & Bennis 1979, image motion vs. minimal temporal
# stimulation); high frequencies fall from about 8 Hz as in Robson (1966). Same precision as
# above (+-0.1 log10; the peak heights are the papers' stated maxima, the rest is the curves'
# shape).
TOLHURST73 = {
    0.5: (0.0, 0.05, 0.12, 0.20, 0.22, 0.00, -0.70, -2.40),
    2.5: (0.0, 0.08, 0.18, 0.27, 0.26, -0.10, -1.00, -2.70),
    8.0: (0.0, 0.02, 0.05, 0.07, 0.02, -0.45, -1.40, -3.00),
    16.0: (0.0, -0.03, -0.10, -0.22, -0.40, -0.85, -1.70, -3.00),
}
SHAPES = {"robson66": ROBSON66, "tolhurst73": TOLHURST73}

# (name, static person, shape, tf_scale, ecc_k per deg, gain, fall, decision)
PEOPLE = (
    ("robson", "robson", "robson66", 1.00, 0.00, 1.00, 1.00, "weibull"),
    ("older", "older", "robson66", 0.80, 0.01, 0.80, 1.20, "sdt"),
    ("mkgp", "mkgp", "tolhurst73", 1.00, 0.02, 1.00, 1.00, "weibull"),
    ("virsu", "virsu", "tolhurst73", 1.15, 0.03, 1.30, 0.85, "sdt"),
    ("mesopic", "mesopic", "robson66", 0.55, 0.00, 0.70, 1.00, "weibull"),
    ("dog", "dog", "tolhurst73", 0.90, 0.01, 1.20, 1.10, "sdt"),
    ("mansak", "mansak", "robson66", 1.10, 0.02, 1.15, 0.90, "weibull"),
)


def interp(xs, ys, x):
    """Piecewise linear, ys[0] below xs[0], the last segment extended above xs[-1]."""
    if x <= xs[0]:
        return ys[0]
    for i in range(1, len(xs)):
        if x <= xs[i] or i == len(xs) - 1:
            a = (x - xs[i - 1]) / (xs[i] - xs[i - 1])
            return ys[i - 1] + a * (ys[i] - ys[i - 1])
    return ys[-1]


def shape_ratio(shape, f, tf):
    """R_shape(f, tf): in log2 tf along each frequency row, then in log2 f between rows."""
    ltf = [math.log2(t) for t in TF_NODES]
    rows = sorted(shape)
    at = [interp(ltf, shape[r], math.log2(tf)) if tf > TF_NODES[0] else 0.0 for r in rows]
    return interp([math.log2(r) for r in rows], at, math.log2(f)) if len(rows) > 1 else at[0]


def person_ratio(p, f, e, v):
    _, _, shape, tf_scale, ecc_k, gain, fall, _ = p
    if v <= 0.0:
        return 0.0
    r0 = shape_ratio(SHAPES[shape], f, f * v / (tf_scale * (1.0 + ecc_k * e)))
    return gain * max(r0, 0.0) + fall * min(r0, 0.0)


def read_static(name):
    rows = {}
    with open("../observer_%s.csv" % name) as src:
        for line in src:
            parts = line.strip().split(",")
            if not parts[0] or parts[0].startswith(("#", "freq")):
                continue
            rows[(float(parts[0]), float(parts[1]))] = float(parts[2])
    return rows


def write_person(p):
    static = read_static(p[1])
    with open("observer_v_%s.csv" % p[0], "w") as out:
        out.write("freq_cpd,ecc_deg,velocity_dps,threshold\n")
        for v in VELS:
            for (f, e), t in sorted(static.items(), key=lambda kv: (kv[0][1], kv[0][0])):
                lt = math.log10(t) - person_ratio(p, f, e, v) if t < 1.0 else 0.0
                out.write("%.6g,%g,%g,%s\n" % (f, e, v, "inf" if lt >= 0.0 else "%.6g" % 10 ** lt))


def spec(rng, p):
    s = math.exp(rng.uniform(math.log(1.5), math.log(6.0)))
    lapse = rng.uniform(0.0, 0.08)
    path = "bench/data/velocity/observer_v_%s.csv" % p[0]
    label = "%s/%s" % (p[0], p[2])
    if p[7] == "sdt":
        k = s / 1.21
        return '{"%s, sdt k %.2f/%.3f", "sim:decision=sdt,k=%.3f,lapse=%.3f,table=%s"},' % (
            label, k, lapse, k, lapse, path)
    return '{"%s, Weibull %.2f/%.3f", "sim:slope=%.3f,lapse=%.3f,table=%s"},' % (
        label, s, lapse, s, lapse, path)


if __name__ == "__main__":
    rng = random.Random(SEED)
    for person in PEOPLE:
        write_person(person)
        print("    " + spec(rng, person))
