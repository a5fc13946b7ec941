#!/bin/bash
# csfcal observer calibrate end to end (simulated observer, headless): tables written and
# readable, JSON summary, invisible cells as "never visible", an unreliable observer refused with
# nothing written, bad input refused with the limit, finished sessions not resumable.
# $1 = csfcal executable.
set -u
CSFCAL="$1"
T=$(mktemp -d /tmp/csfcal-obs-XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
check() { # check DESCRIPTION COMMAND...
    local what="$1"; shift
    if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi
}
run() { "$CSFCAL" observer calibrate --headless --store "$T/s.sqlite" --quiet "$@"; }

# 1. fade on a small grid: a table comes out and the reader accepts it.
out=$(run --method fade --freqs 1,4 --eccs 0,10 --trials 60 --seed 3 --out "$T/fade.csflut" --json)
rc=$?
check "fade session exits 0" test $rc -eq 0
check "fade JSON says ok" grep -q '"status":"ok"' <<<"$out"
check "fade JSON counts catch trials" grep -q '"catch":[1-9]' <<<"$out"
check "fade table written" test -s "$T/fade.csflut"
info=$("$CSFCAL" lut info "$T/fade.csflut")
check "table method is fade" grep -q 'method *fade' <<<"$info"
check "table has 2 x 2 nodes" grep -q 'nodes: *4' <<<"$info"
check "table names the simulated observer" grep -q 'observer *sim(' <<<"$info"

# 2. 2afc session with a plot.
out=$(run --method 2afc --freqs 2,8 --eccs 0 --trials 40 --seed 4 --out "$T/afc.csflut" --plot "$T/afc.png" --json)
check "2afc session ok" grep -q '"status":"ok"' <<<"$out"
check "2afc plot written" test -s "$T/afc.png"

# 3. Invisible cells: a weak observer cannot see 16 cpd at 20 deg at any contrast.
out=$(run --method fade --observer sim:smax=20 --freqs 1,16 --eccs 0,20 --trials 60 --seed 5 --out "$T/inv.csflut" --json)
check "weak observer session ok" grep -q '"status":"ok"' <<<"$out"
check "some cells not visible" grep -q '"not_visible":[1-9]' <<<"$out"
look=$("$CSFCAL" lut lookup "$T/inv.csflut" --freq 16 --ecc 20 --raw)
check "16 cpd at 20 deg never visible" grep -q 'never visible' <<<"$look"
look=$("$CSFCAL" lut lookup "$T/inv.csflut" --freq 1 --ecc 0 --raw)
check "1 cpd in the fovea visible" bash -c "! grep -q 'never visible' <<<\"$look\""

# 4. An unreliable observer (presses on most catch trials) is refused; nothing is written.
err=$(run --method fade --observer sim:fa=0.7 --freqs 1,4 --eccs 0,10 --trials 80 --seed 6 --out "$T/bad.csflut" 2>&1 >/dev/null)
rc=$?
check "unreliable observer: non-zero exit" test $rc -ne 0
check "unreliable observer: says why" grep -q 'not caused by a grating\|catch trials' <<<"$err"
check "unreliable observer: no table" test ! -e "$T/bad.csflut"

# 5. Bad input is refused with the limit.
err=$(run --method fade --trials 0 --out "$T/x.csflut" 2>&1); rc=$?
check "--trials 0 refused" test $rc -eq 2
check "--trials names the range" grep -q '1 to 5000' <<<"$err"
err=$(run --method nope --out "$T/x.csflut" 2>&1); rc=$?
check "--method nope refused" test $rc -eq 2
err=$(run --method fade --freqs 60 --out "$T/x.csflut" 2>&1); rc=$?
check "--freqs above Nyquist refused" test $rc -ne 0
check "Nyquist message names the limit" grep -q 'Nyquist limit of' <<<"$err"
err=$(run --method fade --observer sim:smax=1 --out "$T/x.csflut" 2>&1); rc=$?
check "observer out-of-range key refused" test $rc -ne 0
check "observer message names the range" grep -q 'smax=1 outside 2 to 5000' <<<"$err"
err=$(run --method fade --observer sim:table=$T/none.csv --out "$T/x.csflut" 2>&1); rc=$?
check "missing truth table refused" test $rc -ne 0
err=$(run --out "$T/x.csflut" --method fade --resume 1 2>&1); rc=$?
check "finished session cannot be resumed" test $rc -ne 0
check "resume message says why" grep -q "state 'finished'" <<<"$err"
err=$("$CSFCAL" observer calibrate --headless --store "$T/s.sqlite" 2>&1); rc=$?
check "--out is required" test $rc -eq 2

# 6. A CSV-defined observer (truth not of the parametric form).
printf 'freq_cpd,ecc_deg,threshold\n1,0,0.01\n4,0,0.004\n1,10,0.03\n4,10,0.2\n' >"$T/truth.csv"
out=$(run --method fade --observer "sim:table=$T/truth.csv" --freqs 1,4 --eccs 0,10 --trials 60 --seed 8 --out "$T/tab.csflut" --json)
check "table observer session ok" grep -q '"status":"ok"' <<<"$out"
look=$("$CSFCAL" lut lookup "$T/tab.csflut" --freq 4 --ecc 10 --raw)
v=$(sed -n 's/.*): \([0-9.e+-]*\).*/\1/p' <<<"$look")
check "table observer: 4 cpd at 10 deg within 0.25 log10 of 0.2 (got $v)" awk -v v="$v" 'BEGIN { exit !(v > 0.2 / 1.78 && v < 0.2 * 1.78) }'
# 7. The same seed gives the same table (reproducible simulated sessions).
run --method fade --observer "sim:table=$T/truth.csv" --freqs 1,4 --eccs 0,10 --trials 60 --seed 8 --out "$T/tab2.csflut" >/dev/null
a=$("$CSFCAL" lut export "$T/tab.csflut" --format csv --raw | grep -v date_utc); b=$("$CSFCAL" lut export "$T/tab2.csflut" --format csv --raw | grep -v date_utc)
check "same seed, same thresholds" test "$a" = "$b"

# 8. SIGTERM pauses a running session (every stored trial kept); --resume finishes it.
timeout --preserve-status -s TERM 2 "$CSFCAL" observer calibrate --headless --store "$T/p.sqlite" --quiet --method fade \
    --trials 3000 --seed 9 --out "$T/p.csflut" 2>"$T/p.err"
rc=$?
check "SIGTERM: exit status 1 (paused), got $rc" test $rc -eq 1
check "SIGTERM: message names --resume" grep -q 'paused after .* trials; continue with --resume 1' "$T/p.err"
check "SIGTERM: no table yet" test ! -e "$T/p.csflut"
out=$("$CSFCAL" observer calibrate --headless --store "$T/p.sqlite" --quiet --render-every -1 --resume 1 --out "$T/p.csflut" --json)
check "resumed paused session finishes" grep -q '"status":"ok"' <<<"$out"
check "resumed session wrote the table" test -s "$T/p.csflut"

exit $fail
