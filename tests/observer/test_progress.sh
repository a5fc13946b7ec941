#!/usr/bin/env bash
# The experimenter's progress line: on a terminal (a pseudo-terminal made by script(1)) one line
# redrawn in place with the trial, the cells settled, the time so far and left, and the latest
# flagged trial; nothing redrawn with --quiet or when stderr is a file.
set -u
CSFCAL=$1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
fail=0
err() { echo "FAIL: $*"; fail=1; }
export EGL_PLATFORM=surfaceless
on_tty() { # on_tty OUT ARGS...: csfcal ARGS with stdin, stdout and stderr on a pseudo-terminal
  local out=$1; shift
  local cmd
  cmd=$(printf '%q ' "$CSFCAL" "$@")
  script -qfec "$cmd" "$out" >/dev/null 2>&1
}
on_tty "$T/a" observer calibrate --method fade --observer sim:lapse=0.05,fa=0.1 --seed 4 --trials 40 \
  --store "$T/s.db" --out "$T/a.csflut"
[ -s "$T/a.csflut" ] || err "the session under a terminal wrote no table"
grep -q $'\r\033\\[Kcsfcal: trial 10 of 40 | cells [0-9]*/24 at <= 0.15 | [0-9.]* min so far, [0-9.]* min left' "$T/a" ||
  err "no in-place line for trial 10: $(tr '\r\033' '|~' <"$T/a" | tail -c 400)"
grep -q $'\r\033\\[Kcsfcal: trial 40 of 40 ' "$T/a" || err "no line for the last trial"
grep -q 'last: trial [0-9]* [a-z_]*' "$T/a" || err "no flagged trial named: $(tr '\r\033' '|~' <"$T/a" | tail -c 400)"
# the line is ended before the summary, so the summary starts a line of its own
grep -q $'left[^\r]*\r\r\nobserver session 1' "$T/a" || grep -q $'left[^\r\n]*\r\nobserver session 1' "$T/a" ||
  err "the summary does not start on its own line: $(tr '\r\033' '|~' <"$T/a" | tail -c 300)"
# precision: the predicted error against the target, the time left estimated from its fall
on_tty "$T/b" observer calibrate --observer sim --seed 5 --precision 0.2 --freqs 1,4 --eccs 0,10 \
  --store "$T/s.db" --out "$T/b.csflut"
grep -q 'predicted error [0-9.]* of 0.200 log10 | cells [0-4]/4 at <= 0.20 | .* about [0-9.]* min left' "$T/b" ||
  err "precision line: $(tr '\r\033' '|~' <"$T/b" | tail -c 400)"
# ... and in a log: the periodic line says the time and the trials left, which shrink as it goes
"$CSFCAL" observer calibrate --observer sim --seed 5 --precision 0.15 --store "$T/s.db" --out "$T/p.csflut" \
  2>"$T/p.err" >/dev/null || err "the precision session with stderr to a file failed"
grep -q 'trial 50 (cap [0-9]*): predicted error [0-9.]* log10, target 0.150; [0-9.]* min so far, about [0-9.]* min ([0-9]* trials) left' \
  "$T/p.err" || err "no time left in the periodic precision line: $(tail -c 400 "$T/p.err")"
# --quiet: nothing on the terminal but the summary
on_tty "$T/c" observer calibrate --observer sim --seed 6 --trials 20 --quiet --store "$T/s.db" --out "$T/c.csflut"
grep -q 'csfcal: trial' "$T/c" && err "--quiet drew the progress line"
# stderr to a file: no redrawing, no escape sequences
"$CSFCAL" observer calibrate --observer sim --seed 7 --trials 20 --store "$T/s.db" --out "$T/d.csflut" 2>"$T/d.err" >/dev/null ||
  err "the session with stderr to a file failed"
grep -q $'\033' "$T/d.err" && err "escape sequences written to a file"
grep -q 'csfcal: trial' "$T/d.err" && err "the progress line written to a file"
[ $fail = 0 ] && echo "test_progress: ok"
exit $fail
