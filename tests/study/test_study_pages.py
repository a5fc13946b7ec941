#!/usr/bin/env python3
"""The study report's pages as a reviewer reads them, checked on the PDF's placed words
(pdftotext -bbox-layout) and, for drawn marks, on the page rendered at 72 dpi (pdftoppm: 1 pt =
1 px), for studies answered by the simulated observer (two participants each):

- every word of every page lies inside the page;
- curve pages: markers of one small size, hollow, with the interval visible beyond them (a marker
  sized by its trials covered its interval); at least three labelled ticks in % contrast under the plot, placed on a log axis
  (a tick's x is linear in log10 of its value); the "threshold ..., beta ..." line above the
  plot's top (so never over a marker) with the JSON's t and beta; the table beside it gives every
  curve of the page's scope with the JSON's threshold in %, its interval and beta; the page states
  the threshold criterion with P(t) as the fit gives it;
- every condition label is complete under its slot, long ones wrapped or shrunk, never clipped;
- same/different: a page per scope (pooled and each participant) with hits, false alarms, d' and
  its interval per condition as in the JSON, the interval also in the JSON and the CSV;
- yes/no: each condition's chance line is drawn at its false-alarm rate, not at 0.5.
usage: test_study_pages.py CSFCAL EXAMPLES_DIR
"""
import csv
import html
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

csfcal, examples = sys.argv[1], sys.argv[2]
failures = 0


def check(cond, what):
    global failures
    if not cond:
        failures += 1
        print("FAIL:", what, file=sys.stderr)


def run(*args):
    p = subprocess.run([csfcal, *args], capture_output=True, text=True)
    if p.returncode != 0:
        print(f"csfcal {' '.join(args)}: exit {p.returncode}: {p.stderr}", file=sys.stderr)
        sys.exit(1)
    return p.stdout


def pages_of(pdf):
    """[(width, height, [(xMin, yMin, xMax, yMax, text)])] per page."""
    out = subprocess.run(["pdftotext", "-bbox-layout", pdf, "-"], capture_output=True, text=True,
                         check=True).stdout
    pages = []
    for m in re.finditer(r'<page width="([\d.]+)" height="([\d.]+)">(.*?)</page>', out, re.S):
        words = [(float(a), float(b), float(c), float(d), html.unescape(t)) for a, b, c, d, t in re.findall(
            r'<word xMin="([\d.]+)" yMin="([\d.]+)" xMax="([\d.]+)" yMax="([\d.]+)">([^<]*)</word>', m.group(3))]
        pages.append((float(m.group(1)), float(m.group(2)), words))
    return pages


def lines_of(words):
    """Words grouped into lines (the same yMax within 1 pt: a baseline, whatever a cell's shrunk
    size), each left to right."""
    lines = {}
    for w in words:
        key = next((k for k in lines if abs(k - w[3]) < 1), w[3])
        lines.setdefault(key, []).append(w)
    return [sorted(v) for _, v in sorted(lines.items())]


def page_text(words):
    return "\n".join(" ".join(w[4] for w in line) for line in lines_of(words))


def y_tick(words, label):
    """The box of a y-axis tick label ("0.00", "1.00"): the leftmost such word."""
    c = [w for w in words if w[4] == label and w[0] < 80]
    return min(c) if c else None


def under_axis(words, bottom):
    """Column-joined words between the plot frame and the x axis's name (the lowest "condition"):
    the condition labels as drawn."""
    name = max((w for w in words if w[4] == "condition"), key=lambda w: w[1])
    band = sorted([w for w in words if bottom < w[1] < name[1] - 0.5 and w[2] < 505], key=lambda w: (w[1], w[0]))
    cols = []
    for w in band:
        for c in cols:
            if w[0] < c[1] and w[2] > c[0]:  # overlaps the column in x
                c[2].append(w)
                c[0], c[1] = min(c[0], w[0]), max(c[1], w[2])
                break
        else:
            cols.append([w[0], w[2], [w]])
    return ["".join(x[4] for x in sorted(c[2], key=lambda w: (round(w[1]), w[0]))) for c in cols]


def check_inside(name, pages):
    for i, (pw, ph, words) in enumerate(pages):
        for w in words:
            check(w[0] >= 0 and w[1] >= 0 and w[2] <= pw and w[3] <= ph,
                  f"{name} page {i + 1}: word {w[4]!r} at {w[:4]} outside the {pw} x {ph} page")


def pct(x_log10):
    return f"{100 * 10 ** x_log10:.3g}"


def check_curve_page(name, words, curve, curves_of_scope):
    text = page_text(words)
    top, bottom = y_tick(words, "1.00"), y_tick(words, "0.00")
    check(top and bottom, f"{name}: no y ticks")
    if not (top and bottom):
        return
    # ticks in % on a log axis
    ticks = [w for w in words if re.fullmatch(r"[\d.]+%", w[4]) and bottom[3] < w[1] < bottom[3] + 16]
    check(len(ticks) >= 3, f"{name}: {len(ticks)} labelled x ticks: {[w[4] for w in ticks]}")
    if len(ticks) >= 2:
        xs = [(w[0] + w[2]) / 2 for w in ticks]
        ls = [math.log10(float(w[4][:-1])) for w in ticks]
        slope = (xs[-1] - xs[0]) / (ls[-1] - ls[0]) if ls[-1] != ls[0] else 0
        check(slope > 0, f"{name}: ticks not increasing: {[w[4] for w in ticks]}")
        for x, v, w in zip(xs, ls, ticks):
            check(abs(xs[0] + slope * (v - ls[0]) - x) < 1.5, f"{name}: tick {w[4]} not on the log axis")
    # the fit's line above the plot, with the JSON's t and beta
    fit_line = next((ln for ln in lines_of(words) if ln[0][4] == "threshold"), None)
    check(fit_line is not None, f"{name}: no threshold line")
    if fit_line:
        s = " ".join(w[4] for w in fit_line)
        check(max(w[3] for w in fit_line) < top[1] - 0.5,
              f"{name}: the threshold line (bottom {max(w[3] for w in fit_line)}) reaches into the plot (top "
              f"tick at {top[1]})")
        check(f"t = {curve['t_log10']:.3f}" in s and f"beta = {curve['beta']:.2f}" in s,
              f"{name}: threshold line {s!r} against t {curve['t_log10']}, beta {curve['beta']}")
    # the table: every curve of the scope, with the JSON's figures
    for c in curves_of_scope:
        row = f"{c['curve']} {pct(c['t_log10'])} [{pct(c['t_log10_ci95'][0])}, {pct(c['t_log10_ci95'][1])}] " \
              f"{c['beta']:.2f}"
        check(row in text, f"{name}: table row {row!r} missing:\n{text}")
    p_t = curve["guess"] + (1 - curve["guess"] - curve["lapse"]) * (1 - math.exp(-1))
    flat = " ".join(text.split())
    check("Threshold criterion" in flat and f"P(t) = {p_t:.3f}" in flat and "1 - 1/e" in flat,
          f"{name}: criterion missing or P(t) != {p_t:.3f}:\n{flat}")


def check_labels(name, words, labels):
    bottom = y_tick(words, "0.00")
    if not bottom:
        check(False, f"{name}: no y ticks")
        return
    got = under_axis(words, bottom[3])
    for lab in labels:
        check(lab.replace(" ", "") in got, f"{name}: label {lab!r} not drawn whole: {got}")


def ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    m = re.match(rb"P6\s+(\d+)\s+(\d+)\s+(\d+)\s", data)
    w, h = int(m.group(1)), int(m.group(2))
    return w, h, data[m.end():]


def gray_run(img, x0, x1, y0, y1):
    """Pixels of the chance line's grey (about 0.6) in the box."""
    w, h, px = img
    n = 0
    for y in range(max(0, y0), min(h, y1 + 1)):
        for x in range(max(0, x0), min(w, x1 + 1)):
            r, g, b = px[3 * (y * w + x):3 * (y * w + x) + 3]
            n += 110 <= r <= 215 and abs(r - g) < 12 and abs(r - b) < 12
    return n


with tempfile.TemporaryDirectory() as tmp:
    for f in os.listdir(examples):
        src = os.path.join(examples, f)
        (shutil.copytree if os.path.isdir(src) else shutil.copy)(src, os.path.join(tmp, f))
    # same/different with labels long enough to need wrapping under their slots
    long_labels = {"identical": "identical_pair_shown_twice_in_both_intervals",
                   "fine_detail": "imperceptible-simplification view0 (one code value)",
                   "blob": "perceptible_blob"}
    rows = list(csv.reader(open(os.path.join(tmp, "same_different.csv"))))
    for r in rows[1:]:
        r[0] = long_labels[r[0]]
    with open(os.path.join(tmp, "same_different.csv"), "w", newline="") as f:
        csv.writer(f).writerows(rows)
    reports = {}
    for st in ("contrast_2afc", "yes_no", "same_different"):
        conf, store = os.path.join(tmp, st + ".conf"), os.path.join(tmp, st + ".sqlite")
        for p in ("P01", "P02"):
            run("study", "run", conf, "--participant", p, "--observer", "sim", "--headless", "--quiet",
                "--store", store)
        pdf = os.path.join(tmp, st + ".pdf")
        js = json.loads(run("study", "report", conf, "--store", store, "-o", pdf, "--csv",
                            os.path.join(tmp, st + ".csv"), "--json"))
        reports[st] = (pdf, js, list(csv.DictReader(open(os.path.join(tmp, st + ".csv")))))

    for st, (pdf, js, _) in reports.items():
        check_inside(st, pages_of(pdf))

    # curve pages, in the order the report writes them
    for st in ("contrast_2afc", "yes_no"):
        pdf, js, _ = reports[st]
        pages = pages_of(pdf)
        curves = js["curves"]
        for i, c in enumerate(curves):
            same = [o for o in curves if o["scope"] == c["scope"]]
            check_curve_page(f"{st} curve {c['curve']} ({c['scope']})", pages[i][2], c, same)
        labels = [c["condition"] for c in js["conditions"] if c["scope"] == "pooled"]
        check_labels(f"{st} conditions page", pages[len(curves)][2], labels)

    # markers: one small size, the interval visible beyond them (pooled curve pages of contrast_2afc)
    pdf, js, _ = reports["contrast_2afc"]
    pages = pages_of(pdf)
    for i, c in enumerate(js["curves"]):
        if c["scope"] != "pooled":
            continue
        words = pages[i][2]
        bottom, top = y_tick(words, "0.00"), y_tick(words, "1.00")
        ticks = [w for w in words if re.fullmatch(r"[\d.]+%", w[4]) and bottom[3] < w[1] < bottom[3] + 16]
        xs = [(w[0] + w[2]) / 2 for w in ticks]
        ls = [math.log10(float(w[4][:-1])) for w in ticks]
        if len(ticks) < 2:  # failed above: no axis to place the levels on
            continue
        slope = (xs[-1] - xs[0]) / (ls[-1] - ls[0])
        y0c, y1c = (bottom[1] + bottom[3]) / 2, (top[1] + top[3]) / 2
        for f in os.listdir(tmp):
            if f.startswith("cv"):
                os.unlink(os.path.join(tmp, f))
        subprocess.run(["pdftoppm", "-r", "72", "-f", str(i + 1), "-l", str(i + 1), pdf, os.path.join(tmp, "cv")],
                       check=True)
        img = ppm(next(os.path.join(tmp, f) for f in os.listdir(tmp) if f.startswith("cv")))
        w_px, h_px, px = img

        def dark(x, y):
            r, g, b = px[3 * (y * w_px + x):3 * (y * w_px + x) + 3]
            return max(r, g, b) < 120

        for lv in c["levels"]:
            x = round(xs[0] + slope * (lv["log10_contrast"] + 2 - ls[0]))
            p = lv["k"] / lv["n"]
            y = round(y0c + (y1c - y0c) * p)
            if not 0.03 < p < 0.97:  # on the frame's edge: no row of its own to measure
                continue
            extent = max(max((abs(dx) for dx in range(-20, 21) if dark(x + dx, yy)), default=0)
                         for yy in (y - 1, y, y + 1))
            check(extent <= 6, f"contrast_2afc {c['curve']} level {lv}: marker {extent} px wide each side "
                  "(more than a fixed 3.5 pt marker)")
            away = y + 9 if p >= 0.5 else y - 9  # the interval's longer side, past the marker
            check(any(dark(x + dx, away) for dx in (-1, 0, 1)), f"contrast_2afc {c['curve']} level {lv}: "
                  f"no interval visible at {away} beyond the marker at {y}")

    # same/different: a page per scope with hits, false alarms, d' and its interval
    pdf, js, rows = reports["same_different"]
    pages = pages_of(pdf)
    scopes = ["pooled", "P01", "P02"]
    check(len(pages) == len(scopes), f"same/different: {len(pages)} pages, expected one per scope {scopes}")
    for scope, (_, _, words) in zip(scopes, pages):
        text = page_text(words)
        flat = " ".join(text.split())
        check(f"hits and false alarms, {scope}" in flat, f"same/different page of {scope}: title:\n{text}")
        conds = [c for c in js["conditions"] if c["scope"] == scope]
        check_labels(f"same/different {scope}", words, [c["condition"] for c in conds])
        for c in conds:
            lo, hi = c.get("dprime_ci95", [None, None])
            check(lo is not None and hi is not None and lo <= c["dprime"] <= hi,
                  f"same/different {scope} {c['condition']}: d' {c['dprime']} interval {c['dprime_ci95']}")
            if lo is None or hi is None:
                continue
            cells = (f"{c['hit_rate']:.2f} ({c['hits']}/{c['n_signal']}) {c['fa_rate']:.2f} "
                     f"({c['false_alarms']}/{c['n_noise']}) {c['dprime']:.2f} [{lo:.2f}, {hi:.2f}]")
            check(cells in flat.replace("\u2212", "-"), f"same/different {scope} {c['condition']}: {cells!r} not in"
                  f" the table:\n{text}")
    for r in rows:
        if r["kind"] == "condition":
            check(r["dprime_lo"] != "NA" and r["dprime_hi"] != "NA", f"same/different CSV: no d' interval: {r}")

    # yes/no: the chance line of each condition at its false-alarm rate
    pdf, js, _ = reports["yes_no"]
    pages = pages_of(pdf)
    k = next(i for i, p in enumerate(pages) if "false-alarm rate, pooled" in page_text(p[2]))
    words = pages[k][2]
    subprocess.run(["pdftoppm", "-r", "72", "-f", str(k + 1), "-l", str(k + 1), pdf, os.path.join(tmp, "yn")],
                   check=True)
    img = ppm(next(os.path.join(tmp, f) for f in os.listdir(tmp) if f.startswith("yn") and f.endswith(".ppm")))
    y0c, y1c = [(b[1] + b[3]) / 2 for b in (y_tick(words, "0.00"), y_tick(words, "1.00"))]
    bottom = y_tick(words, "0.00")[3]
    conds = [c for c in js["conditions"] if c["scope"] == "pooled"]
    check(any(c["fa_rate"] >= 0.03 for c in conds), "yes/no: no condition with false alarms to test the line on")
    centres = [sum(w[0] + w[2] for w in words if w[4] == c["condition"] and w[1] > bottom) / 2 for c in conds]
    step = centres[1] - centres[0] if len(centres) > 1 else 400
    for c, xc in zip(conds, centres):
        yf = round(y0c + (y1c - y0c) * c["fa_rate"])
        y_half = round(y0c + (y1c - y0c) * 0.5)
        xa, xb = round(xc - 0.38 * step), round(xc - 0.12 * step)
        if c["fa_rate"] < 0.03:  # on the frame's bottom edge, whose antialiased rows are grey too
            continue
        at_fa = gray_run(img, xa, xb, yf - 3, yf + 3)
        check(at_fa >= 0.3 * (xb - xa), f"yes/no {c['condition']}: no chance line at the false-alarm rate "
              f"{c['fa_rate']} (y {yf}): {at_fa} grey pixels")
        if abs(c["fa_rate"] - 0.5) > 0.1:
            at_half = gray_run(img, xa, xb, y_half - 3, y_half + 3)
            check(at_half < 0.1 * (xb - xa), f"yes/no {c['condition']}: a chance line at 0.5 ({at_half} px)")

print(f"{'FAILED' if failures else 'ok'}: {failures} failure(s)")
sys.exit(1 if failures else 0)
