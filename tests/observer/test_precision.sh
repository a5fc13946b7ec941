#!/bin/bash
# csfcal observer calibrate --precision (simulated person, headless): the session stops when the
# table's predicted RMS error reaches the target, says so with the trials and the person's time;
# a target out of the cap's reach is warned about and run to the cap; bad values refused before any
# trial with nothing stored. JSON read back through python's json module. $1 = csfcal executable.
set -u
CSFCAL="$1"
T=$(mktemp -d /tmp/csfcal-prec-XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
check() { local what="$1"; shift; if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi; }
run() { "$CSFCAL" observer calibrate --headless --observer sim "$@"; }

out=$(run --store "$T/a.sqlite" --precision 0.12 --freqs 1,2,4,8 --eccs 0,10 --seed 5 --out "$T/a.csflut" --json 2>"$T/a.err")
check "precision session ok" python3 -c '
import json,sys
d=json.loads(sys.argv[1])
assert d["status"]=="ok" and d["reached_precision"] is True, d
assert d["predicted_rms_log10"] <= 0.12 and d["precision_log10"] == 0.12
assert 10 <= d["trials"] < 320, d["trials"]        # cap: 40 per cell
assert d["person_s"] > 0' "$out"
check "stored settings keep the target" bash -c "sqlite3 '$T/a.sqlite' 'select settings_json from sessions' | grep -q precision_log10"
# the same without --json: the experimenter's terminal
sum=$(run --store "$T/c.sqlite" --precision 0.12 --freqs 1,2,4,8 --eccs 0,10 --seed 5 --out "$T/c.csflut" 2>"$T/c.err")
check "expected time said first" grep -q "about [0-9]* trials (cap 320) over 8 cells: about .* minutes" "$T/c.err"
check "progress with the predicted error" grep -q "predicted error .* target 0.120" "$T/c.err"
check "summary: predicted error, reached, person time" grep -q "predicted RMS error 0\.[01][0-9]* log10 (--precision reached), person time [0-9.]* min" <<<"$sum"

run --store "$T/d.sqlite" --precision 0.01 --trials 30 --freqs 1,4 --eccs 0 --seed 6 --out "$T/d.csflut" >/dev/null 2>"$T/b.err"
check "unreachable target warned" grep -q "probably out of reach of the cap of 30 trials" "$T/b.err"
out=$(run --store "$T/b.sqlite" --precision 0.01 --trials 30 --freqs 1,4 --eccs 0 --seed 6 --out "$T/b.csflut" --json)
check "unreachable target runs to the cap" python3 -c '
import json,sys
d=json.loads(sys.argv[1]); assert d["status"]=="ok" and d["trials"]==30 and d["reached_precision"] is False, d' "$out"

for bad in 0 -0.1 nan 3; do
    err=$(run --store "$T/r.sqlite" --precision "$bad" --out "$T/r.csflut" 2>&1 >/dev/null); rc=$?
    check "--precision $bad refused" test $rc -ne 0
    check "--precision $bad: says the limit" grep -q "precision.*0.001" <<<"$err"
    check "--precision $bad: nothing stored" test ! -e "$T/r.sqlite"
done
exit $fail
