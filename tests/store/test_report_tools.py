#!/usr/bin/env python3
"""Reports and session exports read back by other people's tools, and written safely.

- pdfinfo: the PDF has a Title; pdftotext: the text is extractable and carries the summary's key
  fields, and each setting value is whole (not wrapped inside a word or a number list).
- The header's person time is the store's (sessions list --json) in minutes, "unknown" where the
  store has none, and left out of a display session's report.
- SVG: no filled dot path starts with a line from elsewhere (the stray hairline from the end of the
  previous text to each "At a glance" dot: a path with both a line-to and the arc's curve-tos).
- Display report: the plot legend names and counts the same readings, failed ones included, as
  the readings table and the stored readings (sessions export), in the table's unit.
- A long display profile id (one that names two profiles after --allow-profile-change) wraps
  inside its cells, in the summary and the settings table, between its parts (word boxes as
  placed in the PDF, from pdftotext -bbox-layout).
- Full disk (RLIMIT_FSIZE with SIGXFSZ ignored, which fails writes like a full disk): report -o
  (pdf, png, svg) and sessions export -o fail with the OS error, leave the previous file as it
  was and no temporary beside it.
- sessions list/show: the resume hint names the command of the session's kind.
"""
import os
import re
import resource
import signal
import sqlite3
import subprocess
import sys
import tempfile

csfcal, make_sample = sys.argv[1], sys.argv[2]
failures = 0
checks = 0


def check(cond, what):
    global failures, checks
    checks += 1
    if not cond:
        failures += 1
        print("FAIL:", what, file=sys.stderr)


def run(*args, expect=0, fsize=None):
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))
    p = subprocess.run([csfcal, *args], capture_output=True, text=True,
                       preexec_fn=limit if fsize is not None else None)
    check(p.returncode == expect, f"csfcal {' '.join(args)}: exit {p.returncode}, expected {expect}; stderr: {p.stderr.strip()}")
    return p


def copy_store(src, dst):
    """A consistent copy of a store to change without touching the original; returns dst."""
    db = sqlite3.connect(src)
    db.execute("VACUUM INTO ?", (dst,))
    db.close()
    return dst


def tool(*args):
    return subprocess.run(list(args), capture_output=True, text=True)


with tempfile.TemporaryDirectory() as tmp:
    store = os.path.join(tmp, "s.sqlite")
    obs, disp = subprocess.run([make_sample, store], capture_output=True, text=True, check=True).stdout.split()
    S = ["--store", store]

    # --- PDF metadata and text ---
    pdf = os.path.join(tmp, "r.pdf")
    run("report", obs, "-o", pdf, *S)
    info = tool("pdfinfo", pdf).stdout
    m = re.search(r"^Title:\s*(.+)$", info, re.M)
    check(m is not None and m.group(1).strip() == f"csfcal session {obs}: observer calibration report",
          f"pdfinfo title: {info}")
    check(re.search(r"^Pages:\s*2$", info, re.M) is not None, f"observer report pages: {info}")
    text = tool("pdftotext", "-layout", pdf, "-").stdout
    for field in ("At a glance", "Kind / state", "observer / finished", "Observer", "sim-observer",
                  "Display", "sim-lcd", "Seed", "77", "Trials", "240 (221 valid", "Settings",
                  "Frame timing", "page 1 of 2", "Contrast sensitivity"):
        check(field in text, f"pdftotext: '{field}' missing")
    # Settings values whole: the frequency list on one line, keys unbroken.
    check("[0.5,1,2,4,8,16,24]" in text and "[0,5,10,20]" in text, "settings values wrapped inside")
    for line in text.splitlines():
        if "freqs_cpd" in line:
            check("[0.5,1,2,4,8,16,24]" in line, f"settings line: {line}")
    # The person time in the header, as the store has it (minutes, one decimal).
    import json
    person_s = json.loads(run("sessions", "list", "--json", *S).stdout)[0]["person_s"]
    check(isinstance(person_s, float) and person_s > 0, f"sample person time {person_s}")
    want = f"{person_s / 60:.1f} min" if isinstance(person_s, float) else "?"
    check(re.search(r"Person time\s+" + re.escape(want), text) is not None,
          f"report header: 'Person time {want}' missing")
    ustore = copy_store(store, os.path.join(tmp, "unknown-person.sqlite"))
    db = sqlite3.connect(ustore)
    db.execute("UPDATE sessions SET person_s = NULL WHERE id = ?", (obs,))
    db.commit()
    db.close()
    updf = os.path.join(tmp, "u.pdf")
    run("report", obs, "-o", updf, "--store", ustore)
    utext = tool("pdftotext", "-layout", updf, "-").stdout
    check(re.search(r"Person time\s+unknown", utext) is not None, "report header: unknown person time")
    dpdf = os.path.join(tmp, "d.pdf")
    run("report", disp, "-o", dpdf, *S)
    dtext = tool("pdftotext", "-layout", dpdf, "-").stdout
    check("display calibration report" in dtext and "Photometer readings" in dtext and "grey" in dtext,
          "display report text")
    check("Person time" not in dtext, "display report: no person time row (no participant)")
    check("No frame intervals" not in dtext, "display report has no empty frame-timing page")

    # --- display plot legend against the readings table and the stored readings ---
    # One r reading failed (in a copy): the table and the legend must both count it, and name the
    # same channels (the legend once folded the dark reading into "grey").
    lstore = copy_store(store, os.path.join(tmp, "legend.sqlite"))
    db = sqlite3.connect(lstore)
    db.execute("UPDATE readings SET status = 'timeout', lum_cdm2 = NULL WHERE session_id = ? AND seq = "
               "(SELECT MIN(seq) FROM readings WHERE session_id = ? AND channel = 'r')", (disp, disp))
    db.commit()
    db.close()
    rows = json.loads(run("sessions", "export", disp, "--format", "json", "--table", "readings",
                          "--store", lstore).stdout)
    rows = rows["readings"] if isinstance(rows, dict) else rows
    stored = {}
    for r in rows:
        n, bad = stored.get(r["channel"], (0, 0))
        stored[r["channel"]] = (n + 1, bad + (r["status"] != "ok"))
    lpdf = os.path.join(tmp, "legend.pdf")
    run("report", disp, "-o", lpdf, "--store", lstore)
    ltext = tool("pdftotext", "-layout", lpdf, "-").stdout
    table = {m.group(1): (int(m.group(2)), int(m.group(3))) for m in
             re.finditer(r"^\s*(dark|white|grey|r|g|b)\s+(\d+)\s+(\d+)\s+\S+\s+\S+", ltext, re.M)}
    legend = {m.group(1): (int(m.group(2)), int(m.group(3) or 0)) for m in
              re.finditer(r"\b(dark|white|grey|r|g|b) \((\d+) readings?(?:, (\d+) not ok)?\)", ltext)}
    check(stored.get("r", (0, 0))[1] == 1 and "dark" in stored, f"sample readings: {stored}")
    check(table == stored, f"readings table {table} != stored readings {stored}")
    check(legend == stored, f"plot legend {legend} != stored readings {stored}")
    check("luminance (cd/m\u00b2)" in ltext, "plot axis in the table's unit (cd/m\u00b2)")

    # --- a long display profile id wraps inside its cells, between its parts, never mid-part ---
    # (the settings table broke "...-e0315651" as "...-e03156" / "51"). Each word's box as placed
    # in the PDF (pdftotext -bbox-layout) must lie inside the cell: settings value column
    # 40 + 92 .. 40 + (842 - 2*40 - 2*18) / 3 pt (results/plot.c draw_settings, first column),
    # summary value 160 .. 160 + 300 pt; the lines joined back must give the id.
    long_id = ("sim-display-lcd-20261123-e0315651 from trial 0, sim-display-oled-20261123-ab12cd34 "
               "from trial 31 (--allow-profile-change)")
    pstore = copy_store(store, os.path.join(tmp, "longid.sqlite"))
    db = sqlite3.connect(pstore)
    db.execute("UPDATE sessions SET settings_json = json_set(settings_json, '$.profile_id', ?), profile_id = ? "
               "WHERE id = ?", (long_id, long_id[:127], obs))
    db.commit()
    db.close()
    ppdf = os.path.join(tmp, "longid.pdf")
    run("report", obs, "-o", ppdf, "--store", pstore)
    import html
    words = [(float(a), float(b), float(c), html.unescape(t)) for a, b, c, t in re.findall(
        r'<word xMin="([\d.]+)" yMin="([\d.]+)" xMax="([\d.]+)" yMax="[\d.]+">([^<]*)</word>',
        tool("pdftotext", "-f", "1", "-l", "1", "-bbox-layout", ppdf, "-").stdout)]

    def cell_lines(label, x_lo, x_hi, want):
        """The lines of the value right of the word `label`, and whether every word fits."""
        key = [w for w in words if w[3] == label and w[0] < x_lo]
        if not key:
            return None, False
        y0 = key[-1][1]
        mine = [w for w in words if x_lo - 1 <= w[0] < x_hi and y0 - 2 <= w[1] < y0 + 80]
        lines = {}
        for w in sorted(mine, key=lambda w: (round(w[1]), w[0])):
            lines.setdefault(round(w[1]), []).append(w)
        text, fits = "", True
        for y in sorted(lines):
            line = " ".join(w[3] for w in lines[y])
            fits &= all(w[2] <= x_hi + 0.5 for w in lines[y])
            text = line if not text else text + ("" if text[-1] in "-_/" else " ") + line
            if len(text) >= len(want):
                break
        return text, fits

    sx = 40 + 92
    got, fits = cell_lines("profile_id", sx, 40 + (842 - 80 - 36) / 3, long_id)
    check(fits, "settings: profile id wider than its cell")
    check(got == long_id, f"settings: profile id broken inside a part: {got!r}")
    got, fits = cell_lines("profile", 160, 460, long_id)
    check(fits, "summary: display profile wider than its cell")
    check(got == long_id, f"summary: display profile broken inside a part: {got!r}")

    # --- hairlines: in the SVG, every filled path that draws an arc starts at the arc ---
    svg = os.path.join(tmp, "r.svg")
    run("report", obs, "-o", svg, *S)
    with open(svg) as f:
        body = f.read()
    body = body.split("</defs>", 1)[-1]  # the glyph outlines are defined before: not drawing
    paths = re.findall(r'<path[^>]* d="([^"]*)"', body)
    check(len(paths) > 20, f"svg paths {len(paths)}")
    stray = [d for d in paths if " C " in f" {d} " and re.search(r"\bL\b", d)]
    check(not stray, f"{len(stray)} arc paths start with a line (stray hairline), e.g. {stray[:1]}")

    # --- full disk: no partial file, old file kept, OS error named ---
    for ext in ("pdf", "png", "svg"):
        out = os.path.join(tmp, f"full.{ext}")
        with open(out, "w") as f:
            f.write("previous contents\n")
        p = run("report", obs, "-o", out, *S, expect=1, fsize=4096)
        check("File too large" in p.stderr, f"report .{ext} on a full disk: {p.stderr.strip()}")
        with open(out) as f:
            check(f.read() == "previous contents\n", f"report .{ext}: previous file changed")
    exp = os.path.join(tmp, "full.csv")
    with open(exp, "w") as f:
        f.write("previous contents\n")
    p = run("sessions", "export", obs, "--format", "csv", "--table", "frames", "-o", exp, *S, expect=1, fsize=4096)
    check("File too large" in p.stderr, f"export on a full disk: {p.stderr.strip()}")
    with open(exp) as f:
        check(f.read() == "previous contents\n", "export: previous file changed")
    leftovers = [n for n in os.listdir(tmp) if n.startswith("full.") and n not in
                 ("full.pdf", "full.png", "full.svg", "full.csv")] + [n for n in os.listdir(tmp) if ".tmp" in n]
    check(not leftovers, f"temporaries left: {leftovers}")
    ok = os.path.join(tmp, "ok.csv")
    run("sessions", "export", obs, "--format", "csv", "-o", ok, *S)
    with open(ok) as f:
        check(f.readline().startswith("session_id,seq,"), "export -o writes the file")

    # --- resume hints name the right command ---
    db = sqlite3.connect(store)
    db.execute("UPDATE sessions SET state = 'paused'")
    db.commit()
    db.close()
    p = run("sessions", *S)
    hint = p.stdout.split("unfinished", 1)[-1]
    check(f"csfcal display calibrate --resume {disp}" in hint, f"display resume hint: {hint}")
    check(f"csfcal observer calibrate --resume {obs}" in hint, f"observer resume hint: {hint}")
    check(f"observer calibrate --resume {disp}" not in hint, "display session sent to observer calibrate")
    p = run("sessions", "show", disp, *S)
    check(f"csfcal display calibrate --resume {disp}" in p.stdout, f"show hint: {p.stdout}")

print(f"{checks} checks, {failures} failed", file=sys.stderr)
sys.exit(1 if failures else 0)
