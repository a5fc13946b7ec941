#!/bin/bash
# csfcal observer calibrate over a velocity axis (simulated person, headless): the grid, the cells
# a display cannot show, the per-trial drift and the 3-D table; bad velocity input refused before
# the first trial with nothing stored. JSON is read back through python's json module.
# $1 = csfcal executable.
set -u
CSFCAL="$1"
T=$(mktemp -d /tmp/csfcal-vel-XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
check() { # check DESCRIPTION COMMAND...
    local what="$1"; shift
    if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi
}
run() { "$CSFCAL" observer calibrate --headless --quiet --set refresh_hz=120 "$@"; }
jget() { python3 -c 'import json,sys; print(json.loads(sys.stdin.read())[sys.argv[1]])' "$1"; }

# 1. bayes over 0, 4, 12 deg/s on a 120 Hz display: 16 cpd at 4 and 12 deg/s and 8 cpd at 12 deg/s
#    alias (v f >= 60 Hz); the default budget is 5 trials per cell shown.
out=$(run --store "$T/a.sqlite" --velocities 12,0,4 --freqs 1,4,8,16 --eccs 0,10 --seed 3 --out "$T/v.csflut" --json)
check "bayes velocity session ok" test "$(jget status <<<"$out")" = ok
check "24 cells" test "$(jget cells <<<"$out")" = 24
check "6 cells cannot be shown" test "$(jget cells_not_shown <<<"$out")" = 6
check "default budget 5 per shown cell" test "$(jget trials <<<"$out")" = 90
check "person time measured" python3 -c 'import json,sys; d=json.loads(sys.argv[1]); assert d["person_s"] > 60 and abs(d["person_s"]-d["expected_person_s"]) < 0.3*d["expected_person_s"]' "$out"
info=$("$CSFCAL" lut info "$T/v.csflut")
check "table has a velocity axis 0 4 12" grep -q 'axis velocity *3 points.*0 4 12' <<<"$info"
check "table has 24 nodes" grep -q 'nodes: *24' <<<"$info"
check "table says what its velocities are" grep -q 'meta velocity_meaning retinal velocity' <<<"$info"
check "table lists the cells never shown" grep -q 'meta cells_not_shown 16 cpd at 4 deg/s, 8 cpd at 12 deg/s, 16 cpd at 12 deg/s (every eccentricity)' <<<"$info"
# the trials: every planned cell can be shown, drift in both directions (random per trial)
"$CSFCAL" sessions export 1 --store "$T/a.sqlite" --format csv > "$T/trials.csv" 2>/dev/null
check "trials exported" test -s "$T/trials.csv"
check "no trial at a cell the display cannot show; both drift directions" python3 - "$T/trials.csv" <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r.get("is_practice", "0") in ("0", "false")]
assert rows, "no trials"
bad = [r for r in rows if abs(float(r["velocity_dps"]) * float(r["freq_cpd"])) >= 60]
assert not bad, bad[:2]
v = [float(r["velocity_dps"]) for r in rows]
assert any(x > 0 for x in v) and any(x < 0 for x in v), "one direction only"
assert set(abs(x) for x in v) <= {0.0, 4.0, 12.0}
PY

# 2. --drift-direction forward: every drifting trial positive
run --store "$T/b.sqlite" --velocities 0,4 --freqs 1,2 --eccs 0 --trials 20 --drift-direction forward --seed 4 --out "$T/f.csflut" >/dev/null 2>&1
"$CSFCAL" sessions export 1 --store "$T/b.sqlite" --format csv > "$T/f.csv" 2>/dev/null
check "forward drift only" python3 -c '
import csv,sys
v=[float(r["velocity_dps"]) for r in csv.DictReader(open(sys.argv[1]))]
assert v and min(v) >= 0 and max(v) == 4' "$T/f.csv"

# 3. refusals before the first trial, nothing stored
refused() { # refused DESCRIPTION PATTERN ARGS...
    local what="$1" pat="$2"; shift 2
    local err rc
    err=$(run --store "$T/r.sqlite" --out "$T/r.csflut" "$@" 2>&1 >/dev/null); rc=$?
    check "$what: non-zero exit" test $rc -ne 0
    check "$what: says '$pat'" grep -q -- "$pat" <<<"$err"
    check "$what: nothing stored" test ! -e "$T/r.sqlite"
    check "$what: no table" test ! -e "$T/r.csflut"
}
refused "negative velocity" "out of range" --velocities 0,-4
refused "NaN velocity" "velocities" --velocities 0,nan
refused "velocity twice" "given twice" --velocities 0,4,4
refused "fade past the refresh limit" "16 cpd allows velocities below 3.75 deg/s" --method fade --velocities 0,4 --freqs 1,16
refused "2afc past the refresh limit" "use --method bayes" --method 2afc --velocities 0,12 --freqs 1,8
refused "budget too small for the grid" "needs at least" --velocities 0,4,12 --trials 10
refused "bad drift direction" "random, forward, backward" --velocities 0,4 --drift-direction sideways
# 4. The static slice of a 3-D table and a static session of the same simulated person agree
#    within their stated errors (bayes, two seeds each; cells visible in both).
run --store "$T/s.sqlite" --freqs 1,2,4,8 --eccs 0,10 --trials 60 --seed 21 --out "$T/static.csflut" >/dev/null 2>&1
run --store "$T/m.sqlite" --velocities 0,4 --freqs 1,2,4,8 --eccs 0,10 --seed 22 --out "$T/moving.csflut" >/dev/null 2>&1
"$CSFCAL" lut export "$T/static.csflut" --format csv --raw > "$T/static.csv"
"$CSFCAL" lut export "$T/moving.csflut" --format csv --raw > "$T/moving.csv"
check "static slice agrees with a static session within the stated errors" python3 - "$T/static.csv" "$T/moving.csv" <<'PY'
import csv, math, sys
def rows(path):
    return [r for r in csv.DictReader(l for l in open(path) if not l.startswith("#"))]
s = {(float(r["freq_cpd"]), float(r["ecc_deg"])): r for r in rows(sys.argv[1])}
m = {(float(r["freq_cpd"]), float(r["ecc_deg"])): r for r in rows(sys.argv[2]) if float(r["velocity_dps"]) == 0}
assert len(s) == 8 and len(m) == 8, (len(s), len(m))
n = ok = 0
for k in s:
    a, b = s[k], m[k]
    ta, tb = float(a["threshold"]), float(b["threshold"])
    if not (math.isfinite(ta) and math.isfinite(tb)):
        continue
    se = math.hypot(float(a["stderr_log10"]), float(b["stderr_log10"]))
    n += 1
    ok += abs(math.log10(ta) - math.log10(tb)) <= 2.0 * se
    print(k, round(math.log10(ta), 3), round(math.log10(tb), 3), "se", round(se, 3))
assert n >= 6 and ok >= n - 1, (n, ok)
PY
# 5. --demo: practice trials with feedback, nothing stored or written
mkdir "$T/demo"
out=$(cd "$T/demo" && "$CSFCAL" observer calibrate --headless --observer sim --demo --velocities 0,4 --store "$T/demo/d.sqlite" --json)
check "demo runs six practice trials" python3 -c 'import json,sys; d=json.loads(sys.argv[1]); assert d["demo"] and d["practice"]==6 and 0<=d["right"]<=6, d' "$out"
check "demo stores and writes nothing" test -z "$(ls -A "$T/demo")"
exit $fail
