#!/usr/bin/env python3
"""Every store csfcal writes, checked by SQLite's own command-line tool (sqlite3, a third-party
program): `PRAGMA integrity_check` says ok and `PRAGMA foreign_key_check` finds nothing after each
command that writes the store: display calibrate, observer calibrate (with a profile, with the
default profile and --plot, killed with SIGKILL mid-session, resumed), sessions abort, and a
reading command (sessions list) that migrates a schema-4 store written by the old code. The rows
mean what they say: no display row is named after a profile id, no file is two half artifact rows,
and an observer session's display and profile join to the display's profile history.
A report (read-only) leaves the store byte for byte unchanged."""
import hashlib
import os
import signal
import subprocess
import sys
import tempfile
import time

csfcal, fixtures = sys.argv[1], sys.argv[2]
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
    check(p.returncode == expect, f"csfcal {' '.join(args)}: exit {p.returncode}, expected {expect}; stderr: {p.stderr.strip()[-400:]}")
    return p


def sql(store, query):
    # a busy timeout, as any reader beside a writing session needs: csfcal holds the write lock
    # for a moment at each stored trial, and the polls below read while it writes
    p = subprocess.run(["sqlite3", "-batch", "-cmd", ".timeout 5000", store, query], capture_output=True, text=True)
    check(p.returncode == 0, f"sqlite3 {query}: {p.stderr.strip()}")
    return p.stdout.strip()


def sound(store, after):
    check(sql(store, "PRAGMA integrity_check") == "ok", f"integrity_check after {after}")
    check(sql(store, "PRAGMA foreign_key_check") == "", f"foreign_key_check after {after}")
    check(sql(store, "SELECT COUNT(*) FROM displays WHERE name IN (SELECT profile_id FROM display_profiles)"
              " OR name IN (SELECT profile_id FROM sessions WHERE profile_id IS NOT NULL)") == "0",
          f"a display row named after a profile id after {after}")
    check(sql(store, "SELECT COUNT(*) FROM artifacts a JOIN artifacts b ON a.session_id = b.session_id"
              " AND a.kind = b.kind AND a.id < b.id WHERE (a.path = '' AND b.content IS NULL)"
              " OR (a.content IS NULL AND b.path = '')") == "0", f"half artifact rows after {after}")
    check(sql(store, "SELECT COUNT(*) FROM sessions s WHERE s.profile_id IS NOT NULL AND s.display <> ''"
              " AND NOT EXISTS (SELECT 1 FROM displays d JOIN display_profiles p ON p.display_id = d.id"
              " WHERE d.name = s.display AND p.profile_id = s.profile_id)") == "0",
          f"observer session's display and profile do not join after {after}")


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


with tempfile.TemporaryDirectory() as tmp:
    store = os.path.join(tmp, "lab.sqlite")
    S = ["--store", store]
    prof = os.path.join(tmp, "lcd.profile")
    run("display", "calibrate", "--photometer", "sim:display=lcd", "--no-render", "--seed", "5",
        "--out", prof, *S)
    sound(store, "display calibrate")
    check(sql(store, "SELECT COUNT(*) FROM artifacts WHERE kind = 'profile' AND path <> '' AND content IS NOT NULL") == "1",
          "display calibrate: one profile row with path and bytes")

    obs = ["observer", "calibrate", "--observer", "sim", "--render-every", "-1", "--quiet"]
    run(*obs, "--out", os.path.join(tmp, "a.csflut"), "--trials", "30", "--freqs", "1,4", "--eccs", "0,10",
        "--seed", "3", "--set", f"display_profile={prof}", *S)
    sound(store, "observer calibrate with a profile")
    row = sql(store, "SELECT display, profile_id FROM sessions WHERE kind = 'observer' ORDER BY id DESC LIMIT 1")
    check(row.startswith("sim:display=lcd|sim-display-lcd") or row.startswith("sim:display=lcd|"),
          f"observer session records the measured display: {row}")
    run(*obs, "--out", os.path.join(tmp, "b.csflut"), "--plot", os.path.join(tmp, "b.pdf"), "--trials", "20",
        "--freqs", "1,4", "--eccs", "0", "--seed", "4", *S)
    sound(store, "observer calibrate with the default profile and --plot")

    # Killed mid-session, then resumed; another killed one is aborted.
    def killed_session(seed):
        last = sql(store, "SELECT MAX(id) FROM sessions")
        p = subprocess.Popen([csfcal, *obs, "--out", os.path.join(tmp, f"k{seed}.csflut"), "--trials", "400",
                              "--freqs", "1,2,4,8", "--eccs", "0,5", "--seed", str(seed), *S],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        # Killed once its session has stored a few trials (polled: sanitizer builds start slowly).
        deadline = time.time() + 60
        while time.time() < deadline and p.poll() is None:
            n = sql(store, f"SELECT COUNT(*) FROM trials WHERE session_id > {last}")
            if n and int(n) >= 10:
                break
            time.sleep(0.05)
        p.send_signal(signal.SIGKILL)
        p.wait()
        sid = sql(store, "SELECT MAX(id) FROM sessions")
        check(sql(store, f"SELECT state FROM sessions WHERE id = {sid}") == "running", "killed while running")
        return sid
    sid = killed_session(6)
    sound(store, "observer calibrate killed by SIGKILL")
    run(*obs, "--out", os.path.join(tmp, "k6.csflut"), "--resume", sid, *S)
    sound(store, "observer calibrate --resume")
    sid = killed_session(7)
    run("sessions", "abort", sid, *S)
    sound(store, "sessions abort")
    check(sql(store, f"SELECT state FROM sessions WHERE id = {sid}") == "aborted", "aborted state")

    # A report opens the store read-only: not a byte changes.
    sql(store, "PRAGMA wal_checkpoint(TRUNCATE)")
    before = digest(store)
    run("report", "1", "-o", os.path.join(tmp, "r.pdf"), *S)
    run("sessions", "export", "2", "--format", "csv", "-o", os.path.join(tmp, "t.csv"), *S)
    check(digest(store) == before, "report / export changed the store")

    # A store written by the schema-4 code, migrated by the first (reading) command.
    old = os.path.join(tmp, "v4.sqlite")
    p = subprocess.run(["sqlite3", "-batch", old, f".read {os.path.join(fixtures, 'schema_v4.sql')}"],
                       capture_output=True, text=True)
    check(p.returncode == 0, f"load v4 fixture: {p.stderr}")
    check(sql(old, "PRAGMA foreign_key_check") == "", "v4 fixture itself is consistent")
    run("sessions", "list", "--store", old)
    sound(old, "migrating a schema-4 store")
    check(sql(old, "SELECT MAX(version) FROM schema_version") == "8", "migrated to 8")
    check(sql(old, "SELECT COUNT(*) FROM sessions WHERE person_s IS NOT NULL") == "0",
          "sessions stored before v7 have an unknown person time")

    # Writing commands refuse someone else's SQLite file without changing a byte (it used to be
    # switched to WAL first), and name /dev/null for what it is.
    foreign = os.path.join(tmp, "photos.sqlite")
    sql(foreign, "CREATE TABLE photos (id INTEGER, name TEXT); INSERT INTO photos VALUES (1, 'a');")
    before = digest(foreign)
    for cmd in (["display", "calibrate", "--photometer", "sim:display=lcd", "--no-render", "--out",
                 os.path.join(tmp, "f.profile")],
                [*obs, "--out", os.path.join(tmp, "f.csflut"), "--trials", "5"]):
        p = subprocess.run([csfcal, *cmd, "--store", foreign], capture_output=True, text=True)
        check(p.returncode != 0 and "not a csfcal store" in p.stderr, f"{cmd[0]} on a foreign file: {p.stderr.strip()}")
        check(digest(foreign) == before and not os.path.exists(foreign + "-wal"), f"{cmd[0]} changed a foreign file")
    check(sql(foreign, "PRAGMA journal_mode") == "delete", "foreign file still in rollback-journal mode")
    p = subprocess.run([csfcal, *obs, "--out", os.path.join(tmp, "n.csflut"), "--trials", "5", "--store", "/dev/null"],
                       capture_output=True, text=True)
    check(p.returncode != 0 and "character device" in p.stderr, f"/dev/null store: {p.stderr.strip()}")

print(f"{checks} checks, {failures} failed", file=sys.stderr)
sys.exit(1 if failures else 0)
