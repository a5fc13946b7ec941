#!/bin/sh
# csfcal stimulus check --velocity (drift measured from rendered frames, JSON read back with
# python's json) and stimulus show: refusals of bad input with a message naming the problem, and
# the window path under Xvfb with scripted keys and a scripted quit.
CSFCAL="$1"
fail=0
err() { echo "FAIL: $*"; fail=1; }
export EGL_PLATFORM=surfaceless
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
small="--headless --screen-px 640x360 --screen-mm 531x299 --distance-mm 570 --photometer sim:display=crt,gamma=2.4"
# jget FILE EXPR: a python expression over the parsed JSON object j
jget() { python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print($2)" "$1"; }

# drift measured: speed within 1 %, continuous, no missed frames
"$CSFCAL" stimulus check --freq 2 --ecc 5 --contrast 0.1 --velocity 3 --frames 60 --levels 0 --json $small \
  >"$T/d.json" 2>"$T/e" || { err "drift check failed"; cat "$T/e"; }
[ "$(jget "$T/d.json" "abs(j['speed_rel_error']) < 0.01 and j['drift']['continuous'] and j['drift']['frames_missed'] == 0")" = True ] \
  || err "drift check: $(cat "$T/d.json")"
[ "$(jget "$T/d.json" "abs(j['requested']['drift_hz'] - 6) < 1e-9")" = True ] || err "drift_hz is not velocity x freq"

# with dropped frames: the phase over a held frame steps 2 pi tf x interval, speed still within 1 %
"$CSFCAL" stimulus check --freq 2 --ecc 5 --contrast 0.1 --velocity -3 --frames 90 --levels 0 --json $small \
  --drop-frame 10 --drop-frame 50 --miss-rate 0.05 >"$T/m.json" 2>"$T/e" || { err "drift check with misses failed"; cat "$T/e"; }
[ "$(jget "$T/m.json" "abs(j['speed_rel_error']) < 0.01 and j['drift']['continuous'] and j['drift']['frames_missed'] >= 2")" = True ] \
  || err "drift with misses: $(cat "$T/m.json")"
[ "$(jget "$T/m.json" "abs(j['drift']['held_step_rad'] - j['drift']['held_step_expected_rad']) < 0.05 and abs(j['drift']['held_step_expected_rad']) > 1.9 * j['drift']['frame_step_rad']")" = True ] \
  || err "held step: $(cat "$T/m.json")"
[ "$(jget "$T/m.json" "j['measured']['velocity_dps'] < 0")" = True ] || err "direction lost"

# aliasing: refused, naming the highest velocity at that frequency
"$CSFCAL" stimulus check --freq 2 --ecc 5 --contrast 0.1 --velocity 15 $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "aliasing velocity accepted"
grep -q "must stay below 15 deg/s" "$T/e" || err "aliasing message: $(cat "$T/e")"
"$CSFCAL" stimulus check --freq 2 --ecc 5 --contrast 0.1 --drop-frame 3 $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "--drop-frame without --velocity accepted"

# show: bad input
"$CSFCAL" stimulus show $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "show without a window or --png accepted"
grep -q -- "--png" "$T/e" || err "show headless message: $(cat "$T/e")"
"$CSFCAL" stimulus show --frames 3 --png "$T/a.png" $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "--frames 3 with a file accepted"
grep -q "DIR/" "$T/e" || err "--frames message: $(cat "$T/e")"
"$CSFCAL" stimulus show --keys fx --png "$T/a.png" $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "unknown --keys accepted"
"$CSFCAL" stimulus show --freq 20 --png "$T/a.png" $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "Nyquist frequency accepted by show"
grep -q "Nyquist limit of" "$T/e" || err "show Nyquist message: $(cat "$T/e")"
"$CSFCAL" stimulus show --freq 2 --velocity 20 --png "$T/a.png" $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "aliasing velocity accepted by show"
"$CSFCAL" stimulus show --png "$T/none/a.png" $small >"$T/o" 2>"$T/e"
[ $? -ne 0 ] || err "PNG into a missing folder accepted"
grep -q "No such file" "$T/e" || err "missing folder message: $(cat "$T/e")"
[ ! -e "$T/a.png" ] || err "a refused show wrote a file"

# a symbolic link to a file: the file behind it is replaced and the link stays (core/file_write)
echo old >"$T/target.png"
ln -s target.png "$T/link.png"
"$CSFCAL" stimulus show --png "$T/link.png" --clean $small >"$T/o" 2>"$T/e" || err "PNG through a link: $(cat "$T/e")"
[ -L "$T/link.png" ] || err "the link was replaced"
head -c 4 "$T/target.png" | grep -q PNG || err "the link's target was not written"

# the window, under Xvfb: keys step frequency (octave), contrast (0.1 log10), eccentricity and
# velocity; a step past the Nyquist limit is refused and noted; the scripted quit ends it
if command -v xvfb-run >/dev/null 2>&1; then
  win="--windowed --screen-px 640x360 --screen-mm 531x299 --distance-mm 570 --photometer sim:display=lcd"
  (unset EGL_PLATFORM; xvfb-run -a -s "-noreset -screen 0 1280x720x24" "$CSFCAL" stimulus show $win \
     --freq 1 --contrast 0.1 --keys "fceev" --quit-after-frames 12 --json) >"$T/w.json" 2>"$T/e" \
    || { err "windowed show failed"; cat "$T/e"; }
  [ "$(jget "$T/w.json" "j['frames'] == 12 and j['freq_cpd'] == 2 and abs(j['contrast'] - 0.1 * 10 ** 0.1) < 1e-9 and j['ecc_deg'] == 2 and j['velocity_dps'] == 1")" = True ] \
    || err "window keys: $(cat "$T/w.json")"
  [ "$(jget "$T/w.json" "abs(j['contrast_measured'] / j['contrast'] - 1) < 0.03")" = True ] \
    || err "window measured contrast: $(cat "$T/w.json")"
  (unset EGL_PLATFORM; xvfb-run -a -s "-noreset -screen 0 1280x720x24" "$CSFCAL" stimulus show $win \
     --freq 2 --keys "fffq" --quit-after-frames 50 --json) >"$T/n.json" 2>"$T/e" \
    || { err "windowed show (refused step) failed"; cat "$T/e"; }
  [ "$(jget "$T/n.json" "j['freq_cpd'] == 4 and 'Nyquist' in j['note'] and j['frames'] < 50")" = True ] \
    || err "refused step / q: $(cat "$T/n.json")"
  # a step clamped where it already is (eccentricity 0, then E) is refused and noted the same way
  (unset EGL_PLATFORM; xvfb-run -a -s "-noreset -screen 0 1280x720x24" "$CSFCAL" stimulus show $win \
     --freq 2 --ecc 0 --keys "Eq" --quit-after-frames 50 --json) >"$T/z.json" 2>"$T/e" \
    || { err "windowed show (eccentricity 0, E) failed"; cat "$T/e"; }
  [ "$(jget "$T/z.json" "j['ecc_deg'] == 0 and 'eccentricity is at its limit of 0 deg' in j['note']")" = True ] \
    || err "E at eccentricity 0 not noted: $(cat "$T/z.json")"
else
  echo "xvfb-run not installed: window path not tested"
fi
exit $fail
