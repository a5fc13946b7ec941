#!/bin/bash
# What a participant sees in a human observer session, from screenshots: `csfcal observer
# calibrate --observer human` in a real GLFW fullscreen window on a private Xvfb, keys injected
# with xdotool, screenshots taken with xwd -root and read by tests/emu/xwd_tool.py:
#   1. the instruction screen: text on the grey field (a trial's blank frame holds only the
#      fixation mark);
#   2. four-place trials: screenshots taken while trials run; the place rings are on screen for
#      0.2 s of each fixation, and one screenshot must show a ring at each of the four places the
#      layout puts at this eccentricity (polar 45, 135, 225, 315 deg, exact flat-screen geometry)
#      and none at the polar angles between them; every stored trial's grating is at one of them;
#   3. the break screen after --break-every 3 trials: text, not the instructions' text;
#   4. Escape: the pause screen, text unlike the other two; S stops: exit 1, the session stored
#      paused with its three trials and the resume command printed; that command, run, finishes it.
# $1 = csfcal, $2 = tests/emu/xwd_tool.py. Skips (77) without Xvfb, xdotool or xwd. Every wait
# has a timeout.
set -u
CSFCAL="$1" XWDTOOL="$2"
. "$(dirname "$0")/../xvfb_lib.sh"
xvfb_need Xvfb xdotool xwd
unset EGL_PLATFORM WAYLAND_DISPLAY
xvfb_scratch screens SPID CPID
die() { echo "FAIL: $*"; for f in "$T"/*.err; do [ -s "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }; done; exit 1; }

W=640 H=360
xvfb_start "$W" "$H"

STORE="$T/s.sqlite" MM_W=531 MM_H=299 DIST=570 ECC=10 RING_DEG=3
# 20 Hz: a loaded machine under ASan keeps up (a frame is missed only after 75 ms)
COMMON=(observer calibrate --observer human --store "$STORE" --set refresh_hz=20 --screen-px ${W}x${H}
        --screen-mm ${MM_W}x${MM_H} --distance-mm $DIST --out "$T/t.csflut")
ntrials() { "$CSFCAL" sessions export 1 --format json --store "$STORE" 2>/dev/null | grep -c '"seq"'; }
state() { "$CSFCAL" sessions --store "$STORE" 2>/dev/null | awk '$1 == 1 { print; exit }'; }
alive() { kill -0 "$CPID" 2>/dev/null; }
start() { TAG="$1"; shift; "$CSFCAL" "${COMMON[@]}" "$@" >"$T/$TAG.out" 2>"$T/$TAG.err" & CPID=$!; }
finish() {
    wait_until 30 bash -c "! kill -0 $CPID 2>/dev/null" || { kill "$CPID"; die "$TAG: csfcal did not exit"; }
    wait "$CPID"; RC=$?; CPID=""
}
wait_window() {
    wait_until 30 bash -c "xdotool search --onlyvisible --name '^csfcal\$' >/dev/null 2>&1" || die "$TAG: no window"
    sleep 0.5
    xdotool mousemove $((W / 2)) $((H / 2)) # no window manager: keyboard focus follows the pointer
}
shot() { xwd -root -silent >"$T/$1.xwd" || die "xwd $1"; }
# text_screen NAME [OTHER]: screenshots NAME until it shows text (other than OTHER.xwd's) (20 s):
# a screen is drawn once the session gets to it, later under load
text_screen() {
    local end=$((SECONDS + 20))
    while :; do
        shot "$1"
        python3 "$XWDTOOL" text "$T/$1.xwd" >/dev/null &&
            { [ -z "${2:-}" ] || python3 "$XWDTOOL" differ "$T/$1.xwd" "$T/$2.xwd" >/dev/null; } && return 0
        [ $SECONDS -ge $end ] && return 1
        sleep 0.3
    done
}
# answer N KEY: presses KEY every 0.5 s until the session has N stored trials (a key before the
# answer screen is ignored)
answer() {
    local n="$1" end=$((SECONDS + 60)); shift
    while [ "$(ntrials)" -lt "$n" ]; do
        alive || die "$TAG: csfcal exited early"
        [ $SECONDS -ge $end ] && die "$TAG: only $(ntrials) of $n trials answered in 60 s"
        xdotool key "$1"
        sleep 0.5
    done
}

# ---- 1. the instruction screen --------------------------------------------------------------
start run --method 2afc --afc 4 --trials 5 --freqs 1 --eccs $ECC --practice 0 --break-every 3 --seed 21
wait_window
wait_until 20 bash -c "[ -n \"\$(\"$CSFCAL\" sessions --store '$STORE' 2>/dev/null | awk '\$1 == 1')\" ]" ||
    die "no session in the store"
check "instructions: text on the field" text_screen instructions

# ---- 2. four-place trials: screenshots while the first three trials run -----------------------
# (a background loop: each xwd takes a fraction of the 0.2 s the rings are up)
(i=0; while :; do xwd -root -silent >"$T/trial_$i.xwd.part" 2>/dev/null && mv "$T/trial_$i.xwd.part" "$T/trial_$i.xwd"; i=$((i + 1)); done) &
SPID=$!
xdotool key space                       # instructions: a key starts
answer 3 i                              # I = upper right
kill "$SPID"; wait "$SPID" 2>/dev/null; SPID=""
rm -f "$T"/*.part
n=$(ls "$T"/trial_*.xwd 2>/dev/null | wc -l)
found=""
for f in "$T"/trial_*.xwd; do
    python3 "$XWDTOOL" rings "$f" $MM_W $MM_H $DIST $ECC $RING_DEG 45,135,225,315 0,90,180,270 >"$T/rings.txt" 2>&1 &&
        { found="$f"; cat "$T/rings.txt"; break; }
done
check "four places: a screenshot (of $n) shows the four rings where the layout puts them" test -n "$found"

# ---- 3. the break screen after three trials --------------------------------------------------
check "break: a text screen other than the instructions" text_screen break instructions
xdotool key space                       # a key goes on

# ---- 4. Escape: the pause screen; S stops, stored paused ---------------------------------------
sleep 1.0
xdotool key Escape
check "pause: a text screen other than the break screen" text_screen pause break
check "pause: not the instructions" python3 "$XWDTOOL" differ "$T/pause.xwd" "$T/instructions.xwd"
xdotool key s
finish
check "stop: exit 1 (paused), rc $RC" test "$RC" -eq 1
check "stop: session stored paused with its 3 trials" test "$(ntrials)" -eq 3 -a -n "$(state | grep paused)"
check "stop: the resume command printed" grep -q 'continue with --resume 1' "$T/run.err"
J=$("$CSFCAL" sessions export 1 --format json --store "$STORE")
check "stored trials: four alternatives, gratings at the layout's places" python3 -c '
import json, sys
t = json.loads(sys.argv[1]); t = t["trials"] if isinstance(t, dict) else t
sys.exit(0 if t and all(x["n_alternatives"] == 4 and round(x["polar_deg"]) % 360 in (45, 135, 225, 315) for x in t) else 1)' "$J"

# ---- 5. resumable: --resume finishes it ---------------------------------------------------------
start resume --resume 1
wait_window
answer 5 i
finish
check "resume: the session ends with 5 trials (rc $RC)" test "$(ntrials)" -eq 5 -a -n "$(state | grep -E 'finished|aborted')"
[ $fail = 0 ] || { for f in "$T"/*.err; do echo "--- $f"; tail -n 12 "$f"; done; }
exit $fail
