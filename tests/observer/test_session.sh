#!/bin/bash
# csfcal observer calibrate end to end (simulated observer, headless): tables written and
# readable, JSON summary, invisible cells as "never visible", an unreliable observer refused with
# nothing written, bad input refused with the limit, finished sessions not resumable, four places
# shown at once (--afc 4) away from the fovea and two intervals at it, --afc kept on resume.
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
json_sid() { sed -n 's/.*"session":\([0-9]*\).*/\1/p' <<<"$1"; }
. "$(dirname "$0")/term_after.sh"

# 1. fade on a small grid: a table comes out and the reader accepts it.
out=$(run --method fade --freqs 1,4 --eccs 0,10 --trials 60 --seed 3 --out "$T/fade.csflut" --json)
rc=$?
check "fade session exits 0" test $rc -eq 0
check "fade JSON says ok" grep -q '"status":"ok"' <<<"$out"
check "fade JSON counts catch trials" grep -q '"catch":[1-9]' <<<"$out"
check "fade table written" test -s "$T/fade.csflut"
info=$("$CSFCAL" lut info "$T/fade.csflut")
check "table method is fade" grep -q 'method *fade' <<<"$info"
check "table states the threshold's definition and the anchors" grep -q "method *fade; anchored by [1-9][0-9]* two-interval trials, yes/no offset [-+]0\.[0-9]* log10; threshold d'=1.2734 (2AFC 81.6%, SDT)" <<<"$info"
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
term_after_trials "$T/p.sqlite" 1 3 "$T/p.err" "$CSFCAL" observer calibrate --headless --store "$T/p.sqlite" \
    --quiet --method fade --trials 3000 --seed 9 --out "$T/p.csflut"
rc=$RC
check "SIGTERM: exit status 1 (paused), got $rc" test $rc -eq 1
check "SIGTERM: message names --resume" grep -q 'paused after .* trials; continue with --resume 1' "$T/p.err"
check "SIGTERM: no table yet" test ! -e "$T/p.csflut"
out=$("$CSFCAL" observer calibrate --headless --store "$T/p.sqlite" --quiet --render-every -1 --resume 1 --out "$T/p.csflut" --json)
check "resumed paused session finishes" grep -q '"status":"ok"' <<<"$out"
check "resumed session wrote the table" test -s "$T/p.csflut"

# 9. Four places shown at once (--afc 4, the default) for peripheral cells, two intervals at the
# fovea; exported trials say which, answers are places 1-4, polar angles are the layout's.
# fields FILE.csv: prints "ecc n_alt signal response polar is_practice" per row, by header name
# (n_alternatives is next to last, before onset_s: flags before it may hold a quoted comma, so
# it is counted from the end).
fields() { awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    { print $c["ecc_deg"], $(NF - 1), $c["signal_interval"], $c["response"], $c["polar_deg"], $c["is_practice"] }' "$1"; }
for m in bayes 2afc; do
    out=$(run --method $m --freqs 1,4 --eccs 0,10 --trials 80 --practice 2 --seed 21 --out "$T/four-$m.csflut" --json)
    check "$m --afc 4 (default): session ok" grep -q '"status":"ok"' <<<"$out"
    check "$m --afc 4: table written" test -s "$T/four-$m.csflut"
    check "$m --afc 4: JSON afc 4, two four-place cells" grep -q '"afc":4,"four_place_cells":2,"four_place_trials":[1-9]' <<<"$out"
    sid=$(json_sid "$out")
    "$CSFCAL" sessions export "$sid" --format csv --store "$T/s.sqlite" -o "$T/four-$m.csv"
    F=$(fields "$T/four-$m.csv")
    check "$m --afc 4: every foveal trial two-interval, answers 1-2" awk '$1 == 0 && !($2 == 2 && $3 >= 1 && $3 <= 2 && $4 >= 1 && $4 <= 2) { exit 1 }' <<<"$F"
    check "$m --afc 4: every main trial at 10 deg four-place, answers 1-4" awk '$1 == 10 && $6 == 0 && !($2 == 4 && $3 >= 1 && $3 <= 4 && $4 >= 1 && $4 <= 4) { exit 1 }' <<<"$F"
    check "$m --afc 4: trials at both layouts" test "$(awk '$6 == 0 { print $2 }' <<<"$F" | sort -u | tr -d '\n')" = 24
    check "$m --afc 4: all four places used" test "$(awk '$2 == 4 { print $3 }' <<<"$F" | sort -u | tr -d '\n')" = 1234
    check "$m --afc 4: polar angle is the signal place's (a, 180-a, 180+a, 360-a, a <= 45)" awk '$2 == 4 {
        p = $5; s = $3; if (s == 1 && !(p > 0 && p <= 45)) exit 1; if (s == 2 && !(p >= 135 && p < 180)) exit 1;
        if (s == 3 && !(p > 180 && p <= 225)) exit 1; if (s == 4 && !(p >= 315 && p < 360)) exit 1 }' <<<"$F"
    check "$m --afc 4: a practice trial with four places" awk '$6 == 1 && $2 == 4 { f = 1 } END { exit !f }' <<<"$F"
    check "$m --afc 4: four-place answers better than chance" awk '$2 == 4 && $6 == 0 { n++; k += $3 == $4 } END { exit !(n > 0 && k / n > 0.4) }' <<<"$F"
done
out=$(run --method bayes --afc 2 --freqs 1,4 --eccs 0,10 --trials 40 --seed 22 --out "$T/two.csflut" --json)
check "--afc 2: session ok, no four-place cells" grep -q '"afc":2,"four_place_cells":0,"four_place_trials":0' <<<"$out"
"$CSFCAL" sessions export "$(json_sid "$out")" --format csv --store "$T/s.sqlite" -o "$T/two.csv"
check "--afc 2: every trial two-interval" awk '!($2 == 2 && $4 >= 1 && $4 <= 2) { exit 1 }' <<<"$(fields "$T/two.csv")"
out=$(run --method fade --freqs 1,4 --eccs 0,10 --trials 40 --seed 23 --out "$T/fade4.csflut" --json)
"$CSFCAL" sessions export "$(json_sid "$out")" --format csv --store "$T/s.sqlite" -o "$T/fade4.csv"
# fade: yes/no trials (n_alternatives 0), then its forced-choice anchors, always two-interval
# (never four places, whatever --afc), in one block at the end: at least 10 of the 40 by default
# (more when every cell is measured before the block is due).
check "fade: yes/no trials, then a block of >= 10 two-interval anchors to the end, whatever --afc" awk '
    $6 == 1 { next } { n++; if ($2 == 2) { k++; if (!first) first = n } else if ($2 != 0 || k) bad = 1 }
    END { exit !(!bad && k >= 10 && first == n - k + 1 && n == 40) }' <<<"$(fields "$T/fade4.csv")"
check "fade: two two-interval practice trials before the anchors" awk '$6 == 1 && $2 == 2 { k++ } END { exit !(k == 2) }' \
    <<<"$(fields "$T/fade4.csv")"
check "fade: the JSON reports the anchors and the measured yes/no - forced choice offset" python3 -c '
import json, math, sys
d = json.loads(sys.argv[1])
sys.exit(not (d["fade_anchor_trials"] >= 10 and abs(d["fade_offset_log10"]) <= 0.4 and 0 < d["fade_offset_sd_log10"] <= 0.1))' "$out"
check "bayes: no fade offset in its JSON (null)" python3 -c '
import json, sys
d = json.loads(sys.argv[1])
sys.exit(not (d["fade_anchor_trials"] == 0 and d["fade_offset_log10"] is None))' "$(sed -n 1p <<<"$(run --method bayes --afc 2 --freqs 1 --eccs 0 --trials 6 --seed 25 --out "$T/b6.csflut" --json)")"
err=$(run --method fade --fade-anchors 0.7 --out "$T/x.csflut" 2>&1); rc=$?
check "--fade-anchors 0.7 refused with exit 2, naming the limit" test $rc -eq 2 -a -n "$(grep -F 'out of range (allowed 0 to 0.5)' <<<"$err")"
err=$("$CSFCAL" observer calibrate --headless --store "$T/fa.sqlite" --method bayes --fade-anchors 0.3 --freqs 1 \
    --eccs 0 --trials 6 --seed 26 --out "$T/fa.csflut" 2>&1 >/dev/null)
check "--fade-anchors with bayes: a note says it is ignored" grep -qF -- "--fade-anchors applies to --method fade only; ignored for --method bayes" <<<"$err"
check "--fade-anchors with bayes: no anchor share among the stored settings" python3 -c '
import json, sqlite3, sys
s = json.loads(sqlite3.connect(sys.argv[1]).execute("SELECT settings_json FROM sessions").fetchone()[0])
sys.exit(not (s["method"] == "bayes" and "fade_anchors" not in s))' "$T/fa.sqlite"
err=$("$CSFCAL" observer calibrate --headless --store "$T/fafc.sqlite" --method fade --afc 4 --freqs 1 --eccs 0 \
    --trials 12 --seed 27 --out "$T/fafc.csflut" 2>&1 >/dev/null)
check "--afc with fade: a note says its anchors are two-interval" grep -qF -- "--afc applies to --method bayes and 2afc; a fade session's anchor trials are two-interval" <<<"$err"
check "--afc 4 with fade: the stored layout is the anchors' two intervals" python3 -c '
import json, sqlite3, sys
s = json.loads(sqlite3.connect(sys.argv[1]).execute("SELECT settings_json FROM sessions").fetchone()[0])
sys.exit(not (s["method"] == "fade" and s["afc"] == 2))' "$T/fafc.sqlite"
err=$(run --afc 3 --out "$T/x.csflut" 2>&1); rc=$?
check "--afc 3 refused with exit 2" test $rc -eq 2
check "--afc 3: message names the allowed values" grep -q "'3' is not allowed (2: two intervals, 4: four places" <<<"$err"

# 10. --afc is kept with the session: paused with four places, resumed with --afc 2 on the
# command line, the resumed trials still show four places.
term_after_trials "$T/r.sqlite" 1 3 "$T/r.err" "$CSFCAL" observer calibrate --headless --store "$T/r.sqlite" \
    --quiet --method bayes --afc 4 --freqs 1,4 --eccs 0,10 --trials 3000 --seed 24 --out "$T/r.csflut"
rc=$RC
check "four-place session paused by SIGTERM (rc $rc)" test $rc -eq 1
n1=$("$CSFCAL" sessions export 1 --format csv --store "$T/r.sqlite" | tail -n +2 | wc -l)
check "settings keep afc 4" grep -qF 'afc\":4' <<<"$("$CSFCAL" sessions show 1 --json --store "$T/r.sqlite")"
term_after_trials "$T/r.sqlite" 1 $((n1 + 3)) "$T/r2.err" "$CSFCAL" observer calibrate --headless \
    --store "$T/r.sqlite" --quiet --render-every -1 --afc 2 --resume 1 --out "$T/r.csflut"
"$CSFCAL" sessions export 1 --format csv --store "$T/r.sqlite" -o "$T/r.csv"
n2=$(tail -n +2 "$T/r.csv" | wc -l)
check "resumed session stored more trials ($n1 -> $n2)" test "$n2" -gt "$n1"
check "resumed trials at 10 deg still four-place" awk '$1 == 10 && $6 == 0 && $2 != 4 { exit 1 }' <<<"$(fields "$T/r.csv")"

exit $fail
