#!/usr/bin/env python3
"""csfcal sessions / report from the command line, on the sample store:
listing (text and JSON), tidy exports that the csv and json modules parse with no options and
whose headers carry units, reports with valid magic bytes, and clear errors with non-zero exit."""
import csv
import io
import json
import math
import os
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


def run(*args, expect=0):
    p = subprocess.run([csfcal, *args], capture_output=True, text=True)
    check(p.returncode == expect, f"csfcal {' '.join(args)}: exit {p.returncode}, expected {expect}; stderr: {p.stderr.strip()}")
    return p


with tempfile.TemporaryDirectory() as tmp:
    store = os.path.join(tmp, "s.sqlite")
    ids = subprocess.run([make_sample, store], capture_output=True, text=True, check=True).stdout.split()
    obs, disp = ids[0], ids[1]
    S = ["--store", store]

    # --- list ---
    p = run("sessions", *S)
    check("ID" in p.stdout and "STATE" in p.stdout and "TRIALS" in p.stdout, "list header")
    lines = [l for l in p.stdout.splitlines() if l.split() and l.split()[0] == obs]
    check(len(lines) == 1 and "observer" in lines[0] and "finished" in lines[0] and " 240 " in lines[0], f"list row: {lines}")
    p = run("sessions", "list", "--json", *S)
    lst = json.loads(p.stdout)
    check(len(lst) == 2 and lst[0]["n_trials"] == 240 and lst[1]["n_readings"] == 41, f"json list {lst}")
    check(lst[1]["kind"] == "display" and lst[0]["seed"] == 77, "json list fields")
    p = run("sessions", "--kind", "display", "--json", *S)
    check([x["id"] for x in json.loads(p.stdout)] == [int(disp)], "--kind filter")
    p = run("sessions", "--state", "running", *S)
    check("No matching sessions" in p.stdout, "--state filter, none running")
    p = run("sessions", "--state", "sleeping", *S, expect=2)
    check("running, paused, finished, aborted" in p.stderr, "bad --state message")
    p = run("sessions", "show", obs, "--json", *S)
    info = json.loads(p.stdout)
    check(json.loads(info["settings_json"])["method"] == "fade", "show settings")

    # --- person time: the sample's is its 30 s of instructions plus every frame and answer ---
    frames = list(csv.DictReader(io.StringIO(run("sessions", "export", obs, "--format", "csv",
                                                 "--table", "frames", *S).stdout)))
    trials = list(csv.DictReader(io.StringIO(run("sessions", "export", obs, "--format", "csv", *S).stdout)))
    want_s = 30.0 + sum(float(r["interval_s"]) for r in frames) + sum(float(r["rt_s"]) for r in trials if r["rt_s"])
    check(len(frames) == 240 * 30 and want_s > 300, f"person time inputs: {len(frames)} frames, {want_s} s")
    check(isinstance(lst[0]["person_s"], float) and abs(lst[0]["person_s"] - want_s) < 1e-6,
          f"json person_s {lst[0].get('person_s')} != {want_s}")
    check("person_s" in lst[1] and lst[1]["person_s"] is None, f"display session person_s: {lst[1]}")
    check(info["person_s"] == lst[0]["person_s"], "show --json person_s")
    p = run("sessions", *S)
    check(p.stdout.splitlines()[0].split()[7:9] == ["PERSON", "MIN"], f"person column header: {p.stdout.splitlines()[0]}")
    rows = {l.split()[0]: l.split() for l in p.stdout.splitlines()[1:] if l.split() and l.split()[0].isdigit()}
    check(rows.get(obs, [""] * 9)[7] == f"{want_s / 60:.1f}", f"person minutes: {rows.get(obs)}")
    check(rows.get(disp, [""] * 9)[7] == "-", f"unknown person time: {rows.get(disp)}")
    p = run("sessions", "show", obs, *S)
    check(f"person time  {want_s / 60:.1f} min ({want_s:.0f} s)" in p.stdout, f"show person time: {p.stdout}")
    p = run("sessions", "show", disp, *S)
    check("person time  -" in p.stdout, "show unknown person time")

    # --- CSV export of trials ---
    p = run("sessions", "export", obs, "--format", "csv", *S)
    rows = list(csv.DictReader(io.StringIO(p.stdout)))
    header = p.stdout.splitlines()[0].split(",")
    for col in ["freq_cpd", "ecc_deg", "orientation_deg", "sigma_deg", "velocity_dps", "mean_lum_cdm2",
                "contrast_requested", "rt_s", "click_x_deg", "valid", "flags"]:
        check(col in header, f"trial CSV column {col}")
    check(len(rows) == 240, f"240 trial rows, got {len(rows)}")
    check([int(r["seq"]) for r in rows] == list(range(240)), "rows ordered by seq")
    for r in rows:
        for k in ["freq_cpd", "ecc_deg", "contrast_requested"]:
            float(r[k])
        check(r["rt_s"] == "" or float(r["rt_s"]) > 0, "rt_s empty or positive")
    check(any(r["flags"] == "missed_frames,late" for r in rows), "quoted flags with a comma survive")
    check(any(r["rt_s"] == "" for r in rows), "missing rt_s is an empty cell")
    onsets = [float(r["onset_s"]) for r in rows]
    check(header[-1] == "onset_s" and all(b > a for a, b in zip(onsets, onsets[1:])) and onsets[0] >= 0,
          "onset_s: the last column, rising on the session clock")
    check(all(len(l.split(",")) >= len(header) for l in p.stdout.splitlines()[1:]), "rows as wide as header")
    freqs = sorted({float(r["freq_cpd"]) for r in rows})
    check(freqs == [0.5, 1, 2, 4, 8, 16, 24], f"frequencies {freqs}")

    # --- JSON export ---
    out = os.path.join(tmp, "trials.json")
    run("sessions", "export", obs, "--format", "json", "-o", out, *S)
    with open(out) as f:
        recs = json.load(f)
    check(isinstance(recs, list) and len(recs) == 240, "json records")
    check(set(recs[0].keys()) == set(header), "json keys = csv header")
    check(any(r["rt_s"] is None for r in recs), "missing = null")
    check(all(isinstance(r["valid"], bool) for r in recs), "booleans")
    check(abs(recs[3]["freq_cpd"] - float(rows[3]["freq_cpd"])) == 0, "csv and json agree exactly")

    # --- display readings and thresholds ---
    p = run("sessions", "export", disp, "--format", "csv", *S)
    rrows = list(csv.DictReader(io.StringIO(p.stdout)))
    check(len(rrows) == 41 and "lum_cdm2" in rrows[0] and "drive01" in rrows[0], "readings export")
    check(rrows[0]["channel"] == "dark" and float(rrows[-1]["lum_cdm2"]) > 5, "reading values")
    p = run("sessions", "export", obs, "--format", "csv", "--table", "thresholds", *S)
    trows = list(csv.DictReader(io.StringIO(p.stdout)))
    check(len(trows) == 28, "28 thresholds")
    inf_rows = [r for r in trows if r["threshold_infinite"] == "1"]
    check(len(inf_rows) > 0 and all(math.isinf(float(r["threshold_michelson"])) for r in inf_rows), "Inf thresholds")
    fin = [r for r in trows if r["threshold_infinite"] == "0"]
    check(all(abs(float(r["sensitivity"]) * float(r["threshold_michelson"]) - 1) < 1e-12 for r in fin), "sensitivity = 1/threshold")
    p = run("sessions", "export", obs, "--format", "json", "--table", "thresholds", *S)
    tj = json.loads(p.stdout)
    check(all((r["threshold_michelson"] is None) == r["threshold_infinite"] for r in tj), "json Inf as null + flag")

    p = run("sessions", "export", obs, "--format", "csv", "--table", "frames", *S)
    frows = list(csv.DictReader(io.StringIO(p.stdout)))
    check(len(frows) == 240 * 30 and set(frows[0]) == {"session_id", "trial_seq", "frame", "interval_s"}, "frames export")
    late = [r for r in frows if float(r["interval_s"]) > 0.025]
    check(len(late) == 6 and all(int(r["trial_seq"]) % 40 == 7 and r["frame"] == "12" for r in late), f"late frames {len(late)}")

    # --- errors ---
    missing = os.path.join(tmp, "nope.csv")
    p = run("sessions", "export", "99", "--format", "csv", "-o", missing, *S, expect=1)
    check("no session 99" in p.stderr and not os.path.exists(missing), "unknown session, no file left")
    p = run("sessions", "export", obs, "--format", "xml", *S, expect=2)
    check("csv, json" in p.stderr, "bad format message")
    p = run("sessions", "export", obs, *S, expect=2)
    p = run("sessions", "export", "abc", "--format", "csv", *S, expect=2)
    p = run("sessions", "frobnicate", *S, expect=2)
    p = run("sessions", "abort", obs, *S, expect=1)
    check("finished" in p.stderr, "cannot abort finished")
    bad = os.path.join(tmp, "bad.sqlite")
    with open(bad, "w") as f:
        f.write("freq,threshold\n1,0.1\n")
    p = run("sessions", "--store", bad, expect=1)
    check("not a database" in p.stderr and bad in p.stderr, f"corrupt store message: {p.stderr}")

    nowhere = os.path.join(tmp, "typo.sqlite")
    p = run("sessions", "--store", nowhere)
    check("No sessions yet" in p.stdout and not os.path.exists(nowhere), "listing does not create a store")
    p = run("sessions", "--json", "--store", nowhere)
    check(json.loads(p.stdout) == [], "empty JSON list")
    p = run("sessions", "export", "1", "--format", "csv", "--store", nowhere, expect=1)
    check("does not exist" in p.stderr and not os.path.exists(nowhere), "export from missing store")
    p = run("report", obs, "-o", os.path.join(tmp, "n.pdf"), "--store", nowhere, expect=1)

    # --- reports ---
    magic = {"pdf": b"%PDF-", "png": b"\x89PNG\r\n\x1a\n", "svg": b"<?xml"}
    for ext, m in magic.items():
        path = os.path.join(tmp, f"r.{ext}")
        run("report", obs, "-o", path, *S)
        with open(path, "rb") as f:
            head = f.read(4096)
        check(head.startswith(m), f"report .{ext} magic")
    path = os.path.join(tmp, "d.png")
    run("report", disp, "-o", path, *S)
    check(os.path.getsize(path) > 10000, "display report size")
    p = run("report", obs, "-o", os.path.join(tmp, "r.gif"), *S, expect=2)
    check(".pdf, .png, .svg" in p.stderr, "bad extension message")
    p = run("report", "42", "-o", os.path.join(tmp, "x.pdf"), *S, expect=1)
    check("no session 42" in p.stderr, "report unknown session")
    p = run("report", obs, *S, expect=2)
    run("report", "--help")
    run("sessions", "--help")

    # --- push: to another store, twice; nothing doubled; no password on the command line ---
    lab = os.path.join(tmp, "lab.sqlite")
    p = run("sessions", "push", "--to", lab, *S)
    check(f"session {obs} -> 1 (new): 240 trials sent, 0 already there" in p.stdout, f"push: {p.stdout}")
    check(f"41 readings sent" in p.stdout, f"push readings: {p.stdout}")
    check(f"240 trials sent, 0 already there; 0 readings sent, 0 already there; 1 artifacts sent" in p.stdout, f"push artifacts: {p.stdout}")
    p = run("sessions", "push", obs, "--to", lab, *S)
    check("0 trials sent, 240 already there" in p.stdout, f"push again: {p.stdout}")
    check("0 artifacts sent" in p.stdout, f"push again artifacts: {p.stdout}")
    p = run("sessions", "list", "--json", "--store", lab)
    check([x["n_trials"] for x in json.loads(p.stdout)] == [240, 0], "pushed listing")
    p = run("sessions", "push", "--to", "postgresql://bob:s3cret@db.lab/csf", *S, expect=2)
    check("s3cret" not in p.stderr and "user=bob dbname=csf host=db.lab" in p.stderr, f"--to password: {p.stderr}")
    p = run("sessions", "list", "--store", "service=lab password=s3cret", expect=2)
    check("s3cret" not in p.stderr and "service=lab" in p.stderr, f"--store password: {p.stderr}")
    p = run("sessions", "push", *S, expect=2)
    check("--to" in p.stderr, "push without --to")
    fresh = os.path.join(tmp, "fresh.sqlite")
    p = run("sessions", "init", "--store", fresh)
    check(os.path.exists(fresh) and "sqlite, schema version 8" in p.stdout, f"init: {p.stdout}")
    p = run("sessions", "init", "extra", "--store", fresh, expect=2)

# --- secrets, names and pasted commands: each attack must fail ---
def sh_words(cmdline):
    """The words a POSIX shell reads from cmdline, by running it (set -- WORDS; print each)."""
    r = subprocess.run(["sh", "-c", "set -- " + cmdline + '; for w in "$@"; do printf "%s\\0" "$w"; done'],
                       capture_output=True)
    check(r.returncode == 0, f"sh could not read {cmdline!r}: {r.stderr!r}")
    return r.stdout.decode().split("\0")[:-1]


with tempfile.TemporaryDirectory() as tmp:
    env = dict(os.environ, XDG_CONFIG_HOME=os.path.join(tmp, "cfg"), XDG_DATA_HOME=os.path.join(tmp, "data"))

    def run_env(*args, expect=0, extra=None):
        p = subprocess.run([csfcal, *args], capture_output=True, text=True, env=dict(env, **(extra or {})))
        check(p.returncode == expect, f"csfcal {' '.join(args)}: exit {p.returncode}, expected {expect}; "
              f"stderr: {p.stderr.strip()}")
        return p

    # A password however libpq would read it: refused from --store, --set, station.conf and
    # --to, and never repeated.
    spellings = ["postgresql://127.0.0.1:1/csf?pass%77ord=Sekr1tA",
                 "postgresql://127.0.0.1:1/csf?%70assword=Sekr1tA",
                 "postgresql://127.0.0.1:1/csf?application_name=x#&password=Sekr1tA",
                 "postgresql://127.0.0.1:1/csf?sslpassword=Sekr1tA"]
    conf = os.path.join(tmp, "station.conf")
    for loc in spellings:
        for args in (["sessions", "list", "--store", loc], ["sessions", "list", "--set", "store=" + loc],
                     ["sessions", "push", "--to", loc, "--store", os.path.join(tmp, "none.sqlite")]):
            p = run_env(*args, expect=2)
            check("Sekr1tA" not in p.stderr + p.stdout and "password" in p.stderr,
                  f"{args}: secret shown or not named: {p.stderr}")
        if "#" not in loc:  # '#' starts a comment in station.conf
            with open(conf, "w") as f:
                f.write(f"store = {loc}\n")
            p = run_env("sessions", "list", "--config", conf, expect=2)
            check("Sekr1tA" not in p.stderr and "station.conf:1" in p.stderr, f"station.conf: {p.stderr}")
    p = run_env("sessions", "list", "--store", "postgresql://127.0.0.1:1/csf?x=Sekr1tA", expect=2)
    check("Sekr1tA" not in p.stderr and "libpq cannot read" in p.stderr, f"unreadable location: {p.stderr}")

    # Rows written past csfcal (sqlite3 directly) with terminal controls in their names: every
    # listing shows them escaped, one row per session, and the JSON stays valid.
    odd = os.path.join(tmp, "lab & co's store", "s.sqlite")
    os.makedirs(os.path.dirname(odd))
    ids = subprocess.run([make_sample, odd], capture_output=True, text=True, check=True).stdout.split()
    evil_obs, evil_disp = "eve\x1b]0;pwned\x07\x1b[2J", "booth\rlcd\x7f\xc2\x9b"
    db = sqlite3.connect(odd)
    db.execute("UPDATE sessions SET observer = ?, display = ?, state = 'running' WHERE id = ?",
               (evil_obs, evil_disp, int(ids[0])))
    db.execute("UPDATE sessions SET tool_version = 'v\x1b[1m', state = 'paused' WHERE id = ?", (int(ids[1]),))
    db.commit()
    db.close()
    for args in (["sessions", "list"], ["sessions", "show", ids[0]], ["sessions", "show", ids[1]]):
        p = run_env(*args, "--store", odd)
        raw = [c for c in p.stdout if (ord(c) < 0x20 and c != "\n") or 0x7f <= ord(c) <= 0x9f]
        check(not raw, f"{args}: raw control characters {raw!r} in {p.stdout!r}")
        check("\\x1b" in p.stdout, f"{args}: ESC not shown escaped: {p.stdout!r}")
    p = run_env("sessions", "list", "--store", odd)
    rows = [l for l in p.stdout.splitlines() if len(l.split()) > 1 and l.split()[0] in ids
            and l.split()[1] in ("observer", "display")]
    check(len(rows) == 2, f"one row per session: {rows}")
    lst = json.loads(run_env("sessions", "list", "--json", "--store", odd).stdout)
    check(lst[0]["observer"] == evil_obs and lst[0]["display"] == evil_disp, f"json names: {lst[0]}")
    # The printed resume command pastes into sh as it is: the store path with '&', spaces and
    # a quote comes back as one word.
    hints = [l.split(": ", 1)[1] for l in p.stdout.splitlines() if "--resume" in l or "sessions abort" in l]
    check(len(hints) == 2, f"resume hints: {p.stdout}")
    for h in hints:
        cmd = h.split(" closes it")[0]
        words = sh_words(cmd)
        check("--store" in words and words[words.index("--store") + 1] == odd, f"hint {h!r} read as {words}")

    # Names refused where they are first read, with the character and its position.
    study = os.path.join(tmp, "s.conf")
    with open(os.path.join(tmp, "s.csv"), "w") as f:
        f.write("label,freq_cpd,ecc_deg,contrast\na,2,5,0.01\n")
    for name, want in (("esc\x1b[31m", "s.conf:1: control character \\x1b at character 11"),
                       ("bell\x07", "s.conf:1: control character \\x07 at character 12"),
                       ("O'Brien", "no quotes")):
        with open(study, "w") as f:
            f.write(f"name = {name}\ndesign = 2afc\nconditions = s.csv\n")
        p = run_env("study", "run", study, "--participant", "P1", "--observer", "sim", "--headless",
                    "--store", os.path.join(tmp, "st.sqlite"), expect=2)
        check(want in p.stderr and "\x1b" not in p.stderr, f"study name {name!r}: {p.stderr!r}")
    with open(study, "w") as f:
        f.write("name = fine\ndesign = 2afc\nconditions = s.csv\n")
    p = run_env("study", "run", study, "--participant", "P\x071", "--observer", "sim", "--headless",
                "--store", os.path.join(tmp, "st.sqlite"), expect=2)
    check("P\\x071" in p.stderr and "\x07" not in p.stderr, f"participant code: {p.stderr!r}")
    # A participant code in a study session's stored settings, rewritten past csfcal with a
    # terminal control (JSON lets "\u001b" through): study report shows it escaped.
    with open(study, "w") as f:
        f.write("name = fine\ndesign = 2afc\nconditions = s.csv\ntrials_per_condition = 10\nbootstrap = 0\n")
    st_store = os.path.join(tmp, "report.sqlite")
    run_env("study", "run", study, "--participant", "P1", "--observer", "sim", "--headless", "--quiet",
            "--store", st_store)
    db = sqlite3.connect(st_store)
    db.execute("UPDATE sessions SET settings_json = replace(settings_json, '\"P1\"', '\"P\\u001b[2J1\"')")
    db.commit()
    db.close()
    p = run_env("study", "report", "fine", "--store", st_store)
    check("P\\x1b[2J1" in p.stdout and "\x1b" not in p.stdout, f"study report participant: {p.stdout!r}")
    p = run_env("display", "calibrate", "--photometer", "sim", "--name", "lcd\r2", "--headless",
                "--out", os.path.join(tmp, "x.profile"), "--store", os.path.join(tmp, "d.sqlite"), expect=2)
    check("\\x0d at character 4" in p.stderr and "\r" not in p.stderr, f"display name: {p.stderr!r}")

    # A trial's text written past csfcal with a terminal control and a byte that is not UTF-8:
    # the JSON export is still JSON (written through jansson), the control escaped by it.
    db = sqlite3.connect(odd)
    db.execute("UPDATE trials SET flags = CAST(X'6c6174651b5b324aff' AS TEXT) WHERE session_id = ? AND seq = 0",
               (int(ids[0]),))
    db.commit()
    db.close()
    p = subprocess.run([csfcal, "sessions", "export", ids[0], "--format", "json", "--store", odd],
                       capture_output=True, env=env)
    check(p.returncode == 0 and b"\x1b" not in p.stdout, f"json export of raw bytes: {p.returncode} {p.stderr!r}")
    try:
        recs = json.loads(p.stdout.decode("utf-8"))
        check(recs[0]["flags"] == "late\\x1b[2J\\xff", f"flags read back as {recs[0]['flags']!r}")
    except (ValueError, UnicodeDecodeError) as e:
        check(False, f"json export of raw bytes is not JSON: {e}")

    # A 332-character observer name is never cut without a word: push refuses it.
    db = sqlite3.connect(odd)
    db.execute("UPDATE sessions SET observer = ? WHERE id = ?", ("n" * 332, int(ids[0])))
    db.commit()
    db.close()
    p = run_env("sessions", "push", ids[0], "--to", os.path.join(tmp, "lab.sqlite"), "--store", odd, expect=1)
    check("longer than 255" in p.stderr, f"long name push: {p.stderr}")

# --- kinds and states this csfcal does not know (a store written by a newer csfcal, or by hand) ---
# The schema CHECKs the words, so a hand that writes others turns the checks off; such a row is
# listed and shown with its stored text escaped, and never taken for a known kind or state.
with tempfile.TemporaryDirectory() as tmp:
    store = os.path.join(tmp, "s.sqlite")
    ids = subprocess.run([make_sample, store], capture_output=True, text=True, check=True).stdout.split()
    obs, disp = ids[0], ids[1]
    S = ["--store", store]
    new_kind, new_state = "survey\x1b[2J", "archived\x07"

    def hand_write(path, sql, args):
        db = sqlite3.connect(path)
        db.execute("PRAGMA ignore_check_constraints = ON")
        db.execute(sql, args)
        db.commit()
        db.close()

    def loosen(path):
        db = sqlite3.connect(path)
        db.execute("PRAGMA writable_schema = ON")
        db.execute("UPDATE sqlite_master SET sql = replace(replace(sql, "
                   "'CHECK (kind IN (''display'', ''observer'', ''study''))', ''), "
                   "'CHECK (state IN (''running'', ''paused'', ''finished'', ''aborted''))', '') "
                   "WHERE name = 'sessions'")
        db.commit()
        db.close()

    def stored(path, sid):
        db = sqlite3.connect(path)
        row = db.execute("SELECT kind, state FROM sessions WHERE id = ?", (int(sid),)).fetchone()
        db.close()
        return row

    hand_write(store, "UPDATE sessions SET kind = ?, state = 'running' WHERE id = ?", (new_kind, int(obs)))
    hand_write(store, "UPDATE sessions SET state = ? WHERE id = ?", (new_state, int(disp)))

    def no_raw(p, what):
        raw = [c for c in p.stdout + p.stderr if (ord(c) < 0x20 and c != "\n") or 0x7f <= ord(c) <= 0x9f]
        check(not raw, f"{what}: raw control characters {raw!r} in {p.stdout!r} {p.stderr!r}")

    p = run("sessions", "list", *S)
    no_raw(p, "list")
    table = p.stdout.split("\n\n")[0].splitlines()[1:]  # the rows, before the resume hints
    rows = {l.split()[0]: l for l in table if l.split()}
    # the table's columns are cut at an escape (shown whole by show and in the hint)
    check(len(rows) == 2 and rows.get(obs, "").split()[1:3] == ["survey", "running"], f"unknown kind listed: {p.stdout!r}")
    check(rows.get(disp, "").split()[1:3] == ["display", "archived"], f"unknown state listed: {p.stdout!r}")
    # the running session of an unknown kind gets the hint that closes it; the unknown state none
    hints = [l for l in p.stdout.splitlines() if "--resume" in l or "sessions abort" in l]
    check(len(hints) == 1 and f"{obs} (survey\\x1b[2J): cannot be resumed" in hints[0], f"hints: {hints}")
    lst = json.loads(run("sessions", "list", "--json", *S).stdout)
    check([x["kind"] for x in lst] == [new_kind, "display"] and lst[1]["state"] == new_state, f"json: {lst}")
    # filters match known words only: neither row is an observer session, nor finished
    check(run("sessions", "--kind", "observer", "--json", *S).stdout.strip() == "[]", "--kind observer")
    check([x["id"] for x in json.loads(run("sessions", "--state", "finished", "--json", *S).stdout)] == [],
          "--state finished")
    check([x["id"] for x in json.loads(run("sessions", "--kind", "display", "--json", *S).stdout)] == [int(disp)],
          "--kind display")
    for sid, want in ((obs, "kind         survey\\x1b[2J"), (disp, "state        archived\\x07")):
        p = run("sessions", "show", sid, *S)
        no_raw(p, f"show {sid}")
        check(want in p.stdout, f"show {sid}: {p.stdout!r}")
    p = run("report", obs, *S, "-o", os.path.join(tmp, "r.svg"))
    check(os.path.getsize(os.path.join(tmp, "r.svg")) > 1000, "report of an unknown kind")

    # A store opened to be written is checked whole first: these rows break its CHECKs, so it
    # is refused as malformed before any session is read.
    p = run("observer", "calibrate", "--resume", obs, *S, "--out", os.path.join(tmp, "o.csflut"), expect=1)
    check("CHECK constraint failed" in p.stderr, f"resume in a store that breaks its CHECKs: {p.stderr!r}")
    # A hand that also took the CHECKs out of the schema: the store opens, and every procedure
    # that would change the session refuses it, naming the stored word escaped.
    loosen(store)
    check("CHECK (state" not in subprocess.run(["sqlite3", store, ".schema sessions"], capture_output=True,
                                              text=True).stdout, "the CHECKs are out of the schema")
    p = run("observer", "calibrate", "--resume", obs, *S, "--out", os.path.join(tmp, "o.csflut"), expect=2)
    no_raw(p, "observer --resume")
    check("survey\\x1b[2J" in p.stderr and "only running or paused observer sessions" in p.stderr,
          f"observer resume of an unknown kind: {p.stderr!r}")
    p = run("display", "calibrate", "--photometer", "sim", "--resume", disp, "--quiet", *S,
            "--out", os.path.join(tmp, "d.profile"), expect=2)
    no_raw(p, "display --resume")
    check("archived\\x07" in p.stderr and "does not know" in p.stderr and "--resume" not in p.stderr,
          f"display resume, refused without a hint to resume: {p.stderr!r}")
    check(not os.path.exists(os.path.join(tmp, "d.profile")), "no profile from a refused resume")
    # abort and push leave a state they do not know alone
    p = run("sessions", "abort", disp, *S, expect=1)
    check("does not know" in p.stderr and "archived\\x07" in p.stderr, f"abort: {p.stderr!r}")
    p = run("sessions", "push", obs, "--to", os.path.join(tmp, "lab.sqlite"), *S, expect=1)
    check("does not know" in p.stderr and "not copied" in p.stderr, f"push: {p.stderr!r}")
    check(stored(store, obs) == (new_kind, "running") and stored(store, disp) == ("display", new_state),
          f"rows changed: {stored(store, obs)} {stored(store, disp)}")

    # a study participant whose session is in a state this csfcal does not know is not resumed
    with open(os.path.join(tmp, "s.csv"), "w") as f:
        f.write("label,freq_cpd,ecc_deg,contrast\na,2,5,0.01\n")
    study = os.path.join(tmp, "s.conf")
    with open(study, "w") as f:
        f.write("name = later\ndesign = 2afc\nconditions = s.csv\ntrials_per_condition = 10\nbootstrap = 0\n")
    st_store = os.path.join(tmp, "study.sqlite")
    run("study", "run", study, "--participant", "P1", "--observer", "sim", "--headless", "--quiet",
        "--store", st_store)
    loosen(st_store)
    hand_write(st_store, "UPDATE sessions SET state = ?", (new_state,))
    p = run("study", "run", study, "--participant", "P1", "--observer", "sim", "--headless", "--quiet",
            "--store", st_store, expect=2)
    no_raw(p, "study run")
    check("archived\\x07" in p.stderr and "does not know" in p.stderr, f"study resume: {p.stderr!r}")
    check(stored(st_store, 1) == ("study", new_state), f"study row changed: {stored(st_store, 1)}")

print(f"{checks} checks, {failures} failed", file=sys.stderr)
sys.exit(1 if failures else 0)
