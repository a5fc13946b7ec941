#!/bin/bash
# csfcal observer calibrate --precision (simulated person, headless): the session stops when the
# table's predicted RMS error reaches the target, says so with the trials and the person's time;
# a target out of the cap's reach is warned about and run to the cap; bad values refused before any
# trial with nothing stored; a paused session resumes, and refuses a replay off its stored cells.
# JSON read back through python's json module. $1 = csfcal executable.
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
assert d["person_s"] > 0
lo, hi = d["expected_person_s_range"]               # where 8 in 10 people fall, about the plan
assert 0 < lo < d["expected_person_s"] < hi, d' "$out"
check "stored settings keep the target" bash -c "sqlite3 '$T/a.sqlite' 'select settings_json from sessions' | grep -q precision_log10"
# the same without --json: the experimenter's terminal
sum=$(run --store "$T/c.sqlite" --precision 0.12 --freqs 1,2,4,8 --eccs 0,10 --seed 5 --out "$T/c.csflut" 2>"$T/c.err")
check "expected time said first" grep -q "about [0-9]* trials (cap 320) over 8 cells: about .* minutes" "$T/c.err"
check "with the range most people fall in" grep -q "minutes of the person's time (8 in 10 people: [0-9.]* to [0-9.]*)" "$T/c.err"
out=$(run --store "$T/f.sqlite" --trials 12 --freqs 1,4 --eccs 0 --seed 5 --out "$T/f.csflut" --json 2>/dev/null)
check "a fixed budget says no range" python3 -c '
import json,sys
d=json.loads(sys.argv[1]); assert d["status"]=="ok" and d["expected_person_s_range"] is None and d["expected_person_s"] > 0, d' "$out"
check "progress with the predicted error" grep -q "predicted error .* target 0.120" "$T/c.err"
check "summary: predicted error, reached, person time" grep -q "predicted RMS error 0\.[01][0-9]* log10 (--precision reached), person time [0-9.]* min" <<<"$sum"

run --store "$T/d.sqlite" --precision 0.01 --trials 30 --freqs 1,4 --eccs 0 --seed 6 --out "$T/d.csflut" >/dev/null 2>"$T/b.err"
check "unreachable target warned" grep -q "probably out of reach of the cap of 30 trials" "$T/b.err"
out=$(run --store "$T/b.sqlite" --precision 0.01 --trials 30 --freqs 1,4 --eccs 0 --seed 6 --out "$T/b.csflut" --json)
check "unreachable target runs to the cap" python3 -c '
import json,sys
d=json.loads(sys.argv[1]); assert d["status"]=="ok" and d["trials"]==30 and d["reached_precision"] is False, d' "$out"

# A cap below the stop's minimum (10 trials): the session runs to the cap, and says the target
# was reached when its table's predicted error is at it (fade's ramps give 0.07 after six here).
out=$(run --method fade --fade-anchors 0 --store "$T/e.sqlite" --precision 0.5 --trials 6 --freqs 1,2 --eccs 0 \
    --seed 23 --out "$T/e.csflut" --json --practice 0 2>/dev/null)
check "a cap below the stop's minimum: reached as the predicted error says" python3 -c '
import json,sys
d=json.loads(sys.argv[1])
assert d["status"]=="ok" and d["trials"]==6 and d["predicted_rms_log10"] <= 0.5 and d["reached_precision"] is True, d' "$out"

# A paused fade session under --precision resumes to its stop. A stored trial whose cell the
# replayed plan does not ask for (a csfcal that plans differently since the session started;
# here the store is edited to look so) is refused on --resume, its trials kept.
. "$(dirname "$0")/term_after.sh"
term_after_trials "$T/p.sqlite" 1 12 "$T/p.err" "$CSFCAL" observer calibrate --headless --observer sim --method fade \
  --precision 0.12 --freqs 1,2,4,8 --eccs 0,10 --seed 7 --store "$T/p.sqlite" --out "$T/p.csflut"
check "fade precision session paused" test "$RC" -eq 1
cp "$T/p.sqlite" "$T/q.sqlite"
out=$("$CSFCAL" observer calibrate --headless --resume 1 --store "$T/p.sqlite" --out "$T/p.csflut" --json 2>/dev/null)
check "paused fade session resumes to its stop" python3 -c '
import json,sys
d=json.loads(sys.argv[1]); assert d["status"]=="ok" and d["reached_precision"] is True, d' "$out"
sqlite3 "$T/q.sqlite" "UPDATE trials SET freq_cpd = CASE WHEN freq_cpd = 1 THEN 8 ELSE 1 END
  WHERE session_id = 1 AND seq = (SELECT max(seq) FROM trials WHERE session_id = 1 AND is_practice = 0)"
n=$(sqlite3 "$T/q.sqlite" "SELECT count(*) FROM trials")
err=$("$CSFCAL" observer calibrate --headless --resume 1 --store "$T/q.sqlite" --out "$T/q.csflut" 2>&1 >/dev/null); rc=$?
check "a replay off the stored cells refused" test $rc -ne 0
check "... saying so" grep -q "the replayed plan asks for another cell" <<<"$err"
check "... its trials kept" test "$(sqlite3 "$T/q.sqlite" "SELECT count(*) FROM trials")" -eq "$n"
check "... no table" test ! -e "$T/q.csflut"

# A fade session resumed before its anchors: the time said for the rest counts their screen (the
# instructions are not shown again, the anchors' are), so it is near what the person then spends.
# The pause is made in the store (the last four main trials removed), so no race decides where.
run --method fade --trials 16 --freqs 1,2 --eccs 0 --seed 7 --store "$T/h.sqlite" --out "$T/h.csflut" >/dev/null 2>&1
sqlite3 "$T/h.sqlite" "DELETE FROM trials WHERE session_id = 1 AND seq >= 15;
  DELETE FROM frame_intervals WHERE session_id = 1 AND trial_seq >= 15; DELETE FROM thresholds WHERE session_id = 1;
  UPDATE sessions SET state = 'paused' WHERE id = 1"
rm -f "$T/h.csflut"
out=$("$CSFCAL" observer calibrate --headless --resume 1 --store "$T/h.sqlite" --out "$T/h.csflut" --json 2>/dev/null)
check "resumed fade: the time said includes the anchors' screen" python3 -c '
import json,sys
d=json.loads(sys.argv[1])
assert d["status"]=="ok" and d["fade_anchor_trials"] > 0, d
assert 0.8 <= d["expected_person_s"] / d["person_s"] <= 1.25, d' "$out"

# A resumed --precision session says the trials its plan still holds, within what the cap leaves: the
# same grid's fixed budgets of 20 and 30 give a trial's time, and two resumes of one session, at 5 and
# at 20 trials done, must differ by 15 of them (cap 70, the plan's trials between 50 and 65).
ept() { python3 -c 'import json,sys; print(json.load(sys.stdin)["expected_person_s"])'; }
e20=$(run --trials 20 --freqs 1,2 --eccs 0 --seed 3 --store "$T/j.sqlite" --out "$T/j.csflut" --json 2>/dev/null | ept)
e30=$(run --trials 30 --freqs 1,2 --eccs 0 --seed 3 --store "$T/k.sqlite" --out "$T/k.csflut" --json 2>/dev/null | ept)
run --precision 0.05 --trials 70 --freqs 1,2 --eccs 0 --seed 3 --store "$T/l.sqlite" --out "$T/l.csflut" >/dev/null 2>&1
said=()
for done in 5 20; do
    cp "$T/l.sqlite" "$T/l$done.sqlite"
    keep=$((3 + done)) # the three practice trials come first
    sqlite3 "$T/l$done.sqlite" "DELETE FROM trials WHERE session_id = 1 AND seq >= $keep;
      DELETE FROM frame_intervals WHERE session_id = 1 AND trial_seq >= $keep;
      DELETE FROM thresholds WHERE session_id = 1; UPDATE sessions SET state = 'paused' WHERE id = 1"
    said+=("$("$CSFCAL" observer calibrate --headless --resume 1 --store "$T/l$done.sqlite" --out "$T/l$done.csflut" \
        --json 2>/dev/null | ept)")
done
check "resumed precision session: the time said follows the plan's trials left" python3 -c '
import sys
e20, e30, s5, s20 = map(float, sys.argv[1:5])
per = (e30 - e20) / 10
assert per > 0 and abs((s5 - s20) - 15 * per) < 0.01, (per, s5, s20)' "$e20" "$e30" "${said[0]}" "${said[1]}"

for bad in 0 -0.1 nan 3; do
    err=$(run --store "$T/r.sqlite" --precision "$bad" --out "$T/r.csflut" 2>&1 >/dev/null); rc=$?
    check "--precision $bad refused" test $rc -ne 0
    check "--precision $bad: says the limit" grep -q "precision.*0.001" <<<"$err"
    check "--precision $bad: nothing stored" test ! -e "$T/r.sqlite"
done
exit $fail
