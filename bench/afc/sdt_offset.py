#!/usr/bin/env python3
"""How far apart a two-interval and a four-place threshold sit for an observer who follows
signal-detection theory rather than the high-threshold Weibull the methods fit.

The methods give both layouts one threshold t: the contrast where the Weibull's detection term
F = 1 - exp(-10^(beta (x - t))) reaches 1 - 1/e, with P = g + (1 - g - lapse) F and g = 1/2 or
1/4 (the convention of QUEST and Psi for m alternatives). An SDT observer with d' = (c/alpha)^k
has P = Phi(d'/sqrt 2) with two intervals and P = integral phi(x - d') Phi(x)^3 dx with four
places; fitting the Weibull to each gives thresholds that differ. This prints, for a few
transducer exponents k, the Weibull slope and threshold fitted to each task and the difference.
Needs python3-numpy and python3-scipy (not part of the build). Run: python3 bench/afc/sdt_offset.py
"""
import numpy as np
from scipy.integrate import quad
from scipy.optimize import least_squares
from scipy.stats import norm


def p_four(d):
    return quad(lambda x: norm.pdf(x - d) * norm.cdf(x) ** 3, -10, 10)[0]


def fit_weibull(x, p, guess):
    r = least_squares(lambda q: guess + (1 - guess) * (1 - np.exp(-10 ** (q[0] * (x - q[1])))) - p, [3.0, 0.0])
    return r.x


x = np.linspace(-0.6, 0.3, 60)  # log10 contrast, alpha = 1
print("k    | two intervals: beta, t | four places: beta, t | t4 - t2 (log10)")
for k in (1.5, 2.0, 2.5, 3.0):
    d = 10 ** (k * x)
    b2, t2 = fit_weibull(x, norm.cdf(d / np.sqrt(2)), 0.5)
    b4, t4 = fit_weibull(x, np.array([p_four(v) for v in d]), 0.25)
    print("%.1f  | %.2f, %+.3f          | %.2f, %+.3f        | %+.3f" % (k, b2, t2, b4, t4, t4 - t2))
