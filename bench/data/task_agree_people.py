#!/usr/bin/env python3
"""Draws simulated people for bench_task_agree's out-of-sample checks (fade vs forced choice).

Eight signal-detection people (transducer k log-uniform over 1.65-4.1, lapse 0-0.05, Pieron term
0-0.25 s with exponent 0.4-0.9, yes/no criterion 2.6-3.4 in d' units, one look every 0.05-0.2 s,
ex-Gaussian reaction time mu 0.25-0.45 s, tau 0.03-0.15 s) and four high-threshold (Weibull)
people (slope 2-5, the same lapse and reaction-time ranges). Prints one --person argument a line.
Usage: task_agree_people.py SEED   (a new seed for every new check, drawn before it is run)"""
import math
import random
import sys


def main():
    r = random.Random(int(sys.argv[1]))
    for i in range(12):
        lapse = r.uniform(0, 0.05)
        pk, pb = r.uniform(0, 0.25), r.uniform(0.4, 0.9)
        mu, tau = r.uniform(0.25, 0.45), r.uniform(0.03, 0.15)
        if i < 8:
            k = math.exp(r.uniform(math.log(1.65), math.log(4.1)))
            crit, look = r.uniform(2.6, 3.4), r.uniform(0.05, 0.2)
            print(f"--person sim:decision=sdt,k={k:.3f},lapse={lapse:.3f},pieron_k={pk:.3f},pieron_beta={pb:.2f},"
                  f"criterion={crit:.2f},look={look:.3f},rt_mu={mu:.3f},rt_tau={tau:.3f}")
        else:
            slope = r.uniform(2, 5)
            print(f"--person sim:slope={slope:.3f},lapse={lapse:.3f},pieron_k={pk:.3f},pieron_beta={pb:.2f},"
                  f"rt_mu={mu:.3f},rt_tau={tau:.3f}")


if __name__ == "__main__":
    main()
