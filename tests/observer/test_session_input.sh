#!/bin/bash
# csfcal observer calibrate and bad input or faults: every option, the output paths and
# the grid on this screen are checked before the first trial (exit 2, nothing stored); a stored
# session whose settings cannot run says so once; a table, plot or store write that fails after
# trials were stored leaves the session resumable and prints the command that finishes it; a
# resume with another display profile is refused unless --allow-profile-change, which is recorded.
# $1 = csfcal executable. Needs sqlite3 (scripts/setup.sh); the full-folder cases need a private
# mount namespace (unshare -m, as root) and are skipped without one.
set -u
CSFCAL="$1"
T=$(mktemp -d /tmp/csfcal-obsin-XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
check() { # check DESCRIPTION COMMAND...
    local what="$1"; shift
    if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi
}
run() { "$CSFCAL" observer calibrate --headless --quiet "$@"; }
state() { sqlite3 "$1" "SELECT state FROM sessions WHERE id = $2"; }
ntrials() { sqlite3 "$1" "SELECT count(*) FROM trials WHERE session_id = $2"; }
. "$(dirname "$0")/term_after.sh"

# 1. Refused before the first trial: exit 2, the message names the value and the limit, no store
# is created and no table written. (--trials 10: before the checks existed, these ran a session.)
refused() { # refused NAME TEXT ARGS...
    local name="$1" text="$2"; shift 2
    rm -f "$T/v.sqlite" "$T/v.csflut"
    err=$(run --store "$T/v.sqlite" --trials 10 --out "$T/v.csflut" "$@" 2>&1 >/dev/null)
    local rc=$?
    check "$name: exit 2 (got $rc)" test $rc -eq 2
    check "$name: says '$text'" grep -qF -- "$text" <<<"$err"
    check "$name: nothing stored" test ! -e "$T/v.sqlite"
    check "$name: no table" test ! -e "$T/v.csflut"
}
refused "--freqs 2,2,4" "--freqs: 2 cpd is given twice" --freqs 2,2,4
refused "--eccs 0,5,5" "--eccs: 5 deg is given twice" --eccs 0,5,5
# default screen 531 x 299 mm at 570 mm: the corners are 28 deg out
refused "--eccs 80" "--eccs: 80 deg does not fit on this screen: it reaches 28 deg from the fixation mark at most" --eccs 80
check "--eccs 80: names the largest eccentricity" grep -q 'so the largest eccentricity is 2[0-9.]* deg' <<<"$err"
refused "--freqs 60" "--freqs: 60 cpd at 0 deg is above the local Nyquist limit of" --freqs 60 --eccs 0
refused "--freqs 30 at 20 deg" "--freqs: 30 cpd at 20 deg is above the local Nyquist limit of" --freqs 30 --eccs 20
refused "--out in a missing folder" "cannot write threshold table $T/nodir/x.csflut: folder $T/nodir" --out "$T/nodir/x.csflut"
refused "--out a folder" "threshold table $T is a folder" --out "$T"
refused "--plot in a missing folder" "cannot write report plot $T/nodir/p.png: folder $T/nodir" --plot "$T/nodir/p.png"
refused "--plot .gif" "--plot $T/p.gif: unknown plot format '.gif'" --plot "$T/p.gif"

# Any order is accepted and sorted.
out=$(run --store "$T/o.sqlite" --method 2afc --freqs 8,2 --eccs 10,0 --trials 8 --practice 0 --render-every -1 \
    --out "$T/sorted.csflut" --json)
check "--freqs 8,2 --eccs 10,0: session ok" grep -q '"status":"ok"' <<<"$out"
info=$("$CSFCAL" lut info "$T/sorted.csflut")
check "axes sorted: freq 2 8" grep -q 'axis freq .*cpd: 2 8$' <<<"$info"
check "axes sorted: ecc 0 10" grep -q 'axis ecc .*deg: 0 10$' <<<"$info"

# 2. A session whose stored settings cannot run (a grid value twice) is refused once with the
# reason, marked aborted, its trials kept; it used to fail the same way at every --resume.
run --store "$T/b.sqlite" --method 2afc --freqs 1,4 --eccs 0 --trials 6 --practice 0 --render-every -1 \
    --out "$T/b.csflut" >/dev/null
sqlite3 "$T/b.sqlite" "UPDATE sessions SET state = 'paused', settings_json = replace(replace(settings_json, '[1,4]', '[4,4]'), '[1.0,4.0]', '[4.0,4.0]') WHERE id = 1"
err=$(run --store "$T/b.sqlite" --resume 1 --out "$T/b2.csflut" 2>&1 >/dev/null); rc=$?
check "bad stored settings: exit 2 (got $rc)" test $rc -eq 2
check "bad stored settings: says why" grep -qF "stored settings are not valid: --freqs: 4 cpd is given twice" <<<"$err"
check "bad stored settings: says it is marked aborted" grep -q 'It cannot be resumed and is now marked aborted; its 6 trials stay' <<<"$err"
check "bad stored settings: state aborted" test "$(state "$T/b.sqlite" 1)" = aborted
check "bad stored settings: 6 trials kept" test "$(ntrials "$T/b.sqlite" 1)" = 6
err=$(run --store "$T/b.sqlite" --resume 1 --out "$T/b2.csflut" 2>&1 >/dev/null)
check "bad stored settings: a second --resume says aborted" grep -q "state 'aborted'" <<<"$err"
run --store "$T/b.sqlite" --method 2afc --freqs 1,4 --eccs 0 --trials 6 --practice 0 --render-every -1 \
    --out "$T/b.csflut" >/dev/null
sqlite3 "$T/b.sqlite" "UPDATE sessions SET state = 'paused', settings_json = replace(settings_json, '\"2afc\"', '\"nope\"') WHERE id = 2"
err=$(run --store "$T/b.sqlite" --resume 2 --out "$T/b2.csflut" 2>&1 >/dev/null); rc=$?
check "unknown stored method: exit 2 (got $rc), marked aborted" test $rc -eq 2 -a "$(state "$T/b.sqlite" 2)" = aborted
check "unknown stored method: says why" grep -qF "stored settings are not valid: --method nope: unknown" <<<"$err"

# 3. The store cannot grow (RLIMIT_FSIZE, SIGXFSZ ignored: writes fail with EFBIG) in the middle
# of a session: non-zero exit, the trials so far kept, the command that finishes it printed; the
# session stays resumable (paused, or running when the store refused that write too).
run --store "$T/f.sqlite" --method 2afc --freqs 2 --eccs 0 --trials 1 --practice 0 --out "$T/f0.csflut" >/dev/null
size=$(stat -c %s "$T/f.sqlite")
(ulimit -f $(((size + 65536) / 512)); trap '' XFSZ; exec "$CSFCAL" observer calibrate --headless --quiet \
    --store "$T/f.sqlite" --method 2afc --freqs 1,4 --eccs 0 --trials 400 --practice 0 --seed 5 \
    --out "$T/f.csflut") >/dev/null 2>"$T/f.err"
rc=$?
n1=$(ntrials "$T/f.sqlite" 2)
check "store full: non-zero exit (got $rc)" test $rc -ne 0
check "store full: some trials stored before ($n1)" test "$n1" -gt 0
check "store full: says how many trials are kept" grep -q "trials kept in session 2 of $T/f.sqlite" "$T/f.err"
check "store full: prints the resume command" grep -qF "csfcal observer calibrate --resume 2 --store $T/f.sqlite --out $T/f.csflut" "$T/f.err"
s=$(state "$T/f.sqlite" 2)
check "store full: session resumable (state $s)" test "$s" = paused -o "$s" = running
check "store full: no table" test ! -e "$T/f.csflut"
out=$(run --store "$T/f.sqlite" --resume 2 --render-every -1 --out "$T/f.csflut" --json)
check "store full: --resume finishes" grep -q '"status":"ok"' <<<"$out"
check "store full: table written on resume" test -s "$T/f.csflut"
check "store full: trials kept ($n1 -> $(ntrials "$T/f.sqlite" 2))" test "$(ntrials "$T/f.sqlite" 2)" -ge "$n1"

# 4. A full folder for the table or the plot (a small tmpfs in a private mount namespace): the
# trials are stored, the write fails after them, the session is left paused (it was "running",
# or "finished" when only the plot failed) and the resume command is printed.
mkdir -p "$T/full"
if unshare -m sh -c 'mount -t tmpfs -o size=64k tmpfs "$1"' _ "$T/full" 2>/dev/null; then
    unshare -m sh -c 'mount -t tmpfs -o size=64k tmpfs "$1/full" || exit 99
        dd if=/dev/zero of="$1/full/fill" bs=4k 2>/dev/null
        "$2" observer calibrate --headless --quiet --store "$1/t.sqlite" --method 2afc --freqs 1,4 --eccs 0 \
            --trials 8 --practice 0 --render-every -1 --out "$1/full/x.csflut" --json >"$1/t1.out" 2>"$1/t1.err"
        echo $? >"$1/t1.rc"; ls -A "$1/full" >"$1/t1.ls"' _ "$T" "$CSFCAL"
    rc=$(cat "$T/t1.rc")
    check "table folder full: exit 1 (got $rc)" test "$rc" -eq 1
    check "table folder full: prints the resume command" grep -qF "csfcal observer calibrate --resume 1 --store $T/t.sqlite --out $T/full/x.csflut" "$T/t1.err"
    check "table folder full: 8 trials kept" grep -q "8 trials kept in session 1" "$T/t1.err"
    check "table folder full: session paused" test "$(state "$T/t.sqlite" 1)" = paused
    check "table folder full: names the table and the OS error" grep -q "writing the threshold table $T/full/x.csflut: .*No space left on device" "$T/t1.err"
    check "table folder full: nothing partial left ($(tr '\n' ' ' <"$T/t1.ls"))" test "$(cat "$T/t1.ls")" = fill
    check "table folder full: JSON says resumable" grep -q '"resumable":true' "$T/t1.out"
    out=$(run --store "$T/t.sqlite" --resume 1 --out "$T/full/x.csflut" --json)
    check "table folder full: --resume writes the table" grep -q '"status":"ok"' <<<"$out"
    check "table folder full: table there" test -s "$T/full/x.csflut"
    check "table folder full: finished" test "$(state "$T/t.sqlite" 1)" = finished
    check "table folder full: no trial added" test "$(ntrials "$T/t.sqlite" 1)" = 8

    # the table (360 bytes) fits, the plot (~80 KB) does not
    unshare -m sh -c 'mount -t tmpfs -o size=64k tmpfs "$1/full" || exit 99
        "$2" observer calibrate --headless --quiet --store "$1/t.sqlite" --method 2afc --freqs 1,4 --eccs 0 \
            --trials 8 --practice 0 --render-every -1 --out "$1/full/y.csflut" --plot "$1/full/y.png" \
            >/dev/null 2>"$1/t2.err"
        echo $? >"$1/t2.rc"; ls -A "$1/full" >"$1/t2.ls"' _ "$T" "$CSFCAL"
    rc=$(cat "$T/t2.rc")
    check "plot folder full: exit 1 (got $rc)" test "$rc" -eq 1
    check "plot folder full: prints the resume command with --plot" grep -qF "csfcal observer calibrate --resume 2 --store $T/t.sqlite --out $T/full/y.csflut --plot $T/full/y.png" "$T/t2.err"
    check "plot folder full: says the table was written" grep -q "(the table was written)" "$T/t2.err"
    check "plot folder full: names the OS error" grep -q "y.png.*No space left on device" "$T/t2.err"
    check "plot folder full: the table and no partial plot ($(tr '\n' ' ' <"$T/t2.ls"))" test "$(cat "$T/t2.ls")" = y.csflut
    check "plot folder full: session paused, not finished" test "$(state "$T/t.sqlite" 2)" = paused
    out=$(run --store "$T/t.sqlite" --resume 2 --out "$T/full/y.csflut" --plot "$T/full/y.png" --json)
    check "plot folder full: --resume writes the plot" grep -q '"status":"ok"' <<<"$out"
    check "plot folder full: plot there" test -s "$T/full/y.png"
else
    echo "skip: full-folder cases (no private mount namespace here)"
fi

# 5. --resume with another display profile: refused naming both ids (it mixed two displays in one
# table); --allow-profile-change goes on, recorded in the store and in the table's metadata.
"$CSFCAL" display calibrate --photometer sim:display=lcd --out "$T/a.profile" --store "$T/d.sqlite" --no-render --quiet >/dev/null 2>&1
"$CSFCAL" display calibrate --photometer sim:display=oled --out "$T/b.profile" --store "$T/d.sqlite" --no-render --quiet >/dev/null 2>&1
ida=$(sed -n 's/^id = //p' "$T/a.profile"); idb=$(sed -n 's/^id = //p' "$T/b.profile")
check "two profiles with different ids ($ida, $idb)" test -n "$ida" -a -n "$idb" -a "$ida" != "$idb"
term_after_trials "$T/p.sqlite" 1 3 /dev/null "$CSFCAL" observer calibrate --headless --quiet --store "$T/p.sqlite" \
    --profile "$T/a.profile" --method 2afc --freqs 1,4 --eccs 0 --trials 200 --practice 0 --seed 7 \
    --out "$T/p.csflut"
rc=$RC
n1=$(ntrials "$T/p.sqlite" 1)
check "profile session paused by SIGTERM (rc $rc, $n1 trials)" test $rc -eq 1 -a "$n1" -gt 0
err=$(run --store "$T/p.sqlite" --resume 1 --profile "$T/b.profile" --render-every -1 --out "$T/p.csflut" 2>&1 >/dev/null); rc=$?
check "other profile on resume: exit 2 (got $rc)" test $rc -eq 2
check "other profile on resume: names both ids" grep -qF "measured with display profile '$ida', this run has '$idb'" <<<"$err"
check "other profile on resume: names the override" grep -qF -- "--allow-profile-change" <<<"$err"
check "other profile on resume: nothing added" test "$(ntrials "$T/p.sqlite" 1)" = "$n1"
check "other profile on resume: still paused" test "$(state "$T/p.sqlite" 1)" = paused
# a session stored before its settings kept the profile id: the session row's profile_id decides
sqlite3 "$T/p.sqlite" "UPDATE sessions SET settings_json = replace(settings_json, ',\"profile_id\":\"$ida\"', '') WHERE id = 1"
check "settings without profile_id" bash -c "! sqlite3 \"\$0\" 'SELECT settings_json FROM sessions' | grep -q profile_id" "$T/p.sqlite"
err=$(run --store "$T/p.sqlite" --resume 1 --profile "$T/b.profile" --render-every -1 --out "$T/p.csflut" 2>&1 >/dev/null); rc=$?
check "older session, other profile: refused naming both ids (rc $rc)" grep -qF "measured with display profile '$ida', this run has '$idb'" <<<"$err"
err=$(run --store "$T/p.sqlite" --resume 1 --render-every -1 --out "$T/p.csflut" 2>&1 >/dev/null); rc=$?
check "no --profile on resume: refused (the default model is another profile)" grep -qF "this run has 'default-gamma2.2-100cdm2'" <<<"$err"
out=$(run --store "$T/p.sqlite" --resume 1 --profile "$T/b.profile" --allow-profile-change --render-every -1 \
    --out "$T/p.csflut" --json)
check "--allow-profile-change: session finishes" grep -q '"status":"ok"' <<<"$out"
check "--allow-profile-change: recorded in the store" grep -qF "$n1 $idb" <<<"$(sqlite3 "$T/p.sqlite" \
    "SELECT CAST(content AS TEXT) FROM artifacts WHERE session_id = 1 AND kind = 'profile_change'")"
info=$("$CSFCAL" lut info "$T/p.csflut")
check "--allow-profile-change: the table names both profiles" grep -qF "$ida from trial 0, $idb from trial $n1 (--allow-profile-change)" <<<"$info"

# 5. Nobody asked for the simulator: a headless run without --observer says on stderr, even with
# --quiet, that the simulated observer answered; an explicit --observer sim is not nagged.
XDG_CONFIG_HOME="$T/nocfg" "$CSFCAL" observer calibrate --headless --quiet --trials 6 --practice 0 \
    --store "$T/n.sqlite" --out "$T/n.csflut" 2>"$T/n.err" >/dev/null
check "implicit simulator: announced on stderr" grep -q 'the SIMULATED observer answers' "$T/n.err"
XDG_CONFIG_HOME="$T/nocfg" "$CSFCAL" observer calibrate --headless --quiet --trials 6 --practice 0 \
    --observer sim --store "$T/n2.sqlite" --out "$T/n2.csflut" 2>"$T/n2.err" >/dev/null
check "explicit --observer sim: no note" test ! -s "$T/n2.err"

exit $fail
