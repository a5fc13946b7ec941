#!/bin/bash
# The placement screen a real meter gets before its first reading, in a real GLFW window on a
# private Xvfb, with the emulated LS-100 (tests/emu/emu_minolta) reading what csfcal draws through
# the screen mirror:
#   1. display calibrate waits on the placement screen: a screenshot (xwd) shows the white patch
#      at the centre, the target mark on it and the instructions in the surround; the terminal
#      shows the live reading and "stable"; Space starts the calibration, which finishes (profile
#      written, session finished, its readings stored).
#   2. Escape on the placement screen: exit 1, "left the placement screen", no profile, no session
#      and no reading in the store.
#   3. display verify waits on the same screen; Space, and it verifies the profile of case 1.
# With CSFCAL_PLACEMENT_PNG=FILE the screenshot of case 1 is also written there as a PNG (how
# docs/img/placement.png is made). $1 = csfcal, $2 = emu_minolta, $3 = tests/emu/xwd_tool.py. Skips (77)
# without Xvfb, xdotool or xwd. Every wait has a timeout.
set -u
CSFCAL="$1" EMU="$2" XWDTOOL="$3"
. "$(dirname "$0")/../xvfb_lib.sh"
xvfb_need Xvfb xdotool xwd
unset EGL_PLATFORM WAYLAND_DISPLAY
xvfb_scratch place CPID EPID
die() { echo "FAIL: $*"; for f in "$T"/*.err; do [ -s "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }; done; exit 1; }

W=640 H=360
xvfb_start "$W" "$H"
export CSFCAL_SCREEN_MIRROR="$T/screen"

"$EMU" --path-file "$T/pts" --display lcd --seed 5 >/dev/null 2>"$T/emu.err" &
EPID=$!
wait_until 10 test -s "$T/pts" || die "the emulator did not start"
PORT=$(cat "$T/pts")
GEOM=(--screen-px ${W}x${H} --screen-mm 531x299 --distance-mm 570 --warmup-wait 0 --seed 3)

start() { # TAG ARGS...: csfcal in the background, output in $T/TAG.out / .err
    TAG="$1"; shift
    "$CSFCAL" "$@" >"$T/$TAG.out" 2>"$T/$TAG.err" &
    CPID=$!
}
finish() { # waits for csfcal to exit (60 s), sets RC
    wait_until 60 bash -c "! kill -0 $CPID 2>/dev/null" || { kill "$CPID"; die "$TAG: csfcal did not exit"; }
    wait "$CPID"; RC=$?; CPID=""
}
# the placement screen is up and its reading stable (keys before the window shows would be lost)
wait_stable() {
    wait_until 30 bash -c "xdotool search --onlyvisible --name '^csfcal\$' >/dev/null 2>&1" ||
        die "$TAG: no csfcal window within 30 s"
    wait_until 30 grep -q 'stable, press Space' "$T/$TAG.err" || die "$TAG: the reading never became stable"
    sleep 0.5 # a frame with the stable reading drawn
}
sessions() { python3 -c 'import sqlite3,sys; c=sqlite3.connect(sys.argv[1]); print(c.execute("select count(*) from sessions").fetchone()[0], c.execute("select count(*) from readings").fetchone()[0])' "$1" 2>/dev/null || echo "0 0"; }

# 1. placement, screenshot, Space, the calibration runs to the end
start cal display calibrate --photometer "ls100:$PORT" --store "$T/s.sqlite" --out "$T/a.profile" "${GEOM[@]}"
wait_stable
xwd -root -silent >"$T/shot.xwd" || die "xwd failed"
check "placement screen: patch, mark and instructions in the screenshot" python3 "$XWDTOOL" placement "$T/shot.xwd"
[ -n "${CSFCAL_PLACEMENT_PNG:-}" ] && python3 "$XWDTOOL" png "$T/shot.xwd" "$CSFCAL_PLACEMENT_PNG"
check "placement: the terminal shows the live reading" grep -q 'placement: reading [0-9.]* cd/m2' "$T/cal.err"
check "placement: nothing stored while the meter is being placed" test "$(sessions "$T/s.sqlite")" = "0 0"
xdotool key space
finish
check "calibrate: exit 0 after Space ($RC)" test "$RC" = 0
check "calibrate: profile written" test -s "$T/a.profile"
check "calibrate: one finished session with its readings" python3 -c '
import sqlite3,sys; c=sqlite3.connect(sys.argv[1])
s=c.execute("select state from sessions").fetchall(); n=c.execute("select count(*) from readings").fetchone()[0]
sys.exit(0 if s == [("finished",)] and n > 20 else 1)' "$T/s.sqlite"

# 2. Escape leaves before anything is measured or stored
start esc display calibrate --photometer "ls100:$PORT" --store "$T/e.sqlite" --out "$T/e.profile" "${GEOM[@]}"
wait_stable
xdotool key Escape
finish
check "Escape: exit 1 ($RC)" test "$RC" = 1
check "Escape: says so" grep -q 'left the placement screen with Escape: nothing was measured or stored' "$T/esc.err"
check "Escape: no profile" test ! -e "$T/e.profile"
check "Escape: no session, no reading stored" test "$(sessions "$T/e.sqlite")" = "0 0"

# 3. verify places the meter the same way, then verifies
start ver display verify "$T/a.profile" --photometer "ls100:$PORT" "${GEOM[@]}"
wait_stable
xdotool key space
finish
check "verify: exit 0 after Space ($RC)" test "$RC" = 0
check "verify: ok" grep -q ': ok' "$T/ver.out"
[ $fail = 0 ] || { for f in "$T"/*.err; do echo "--- $f"; tail -n 12 "$f"; done; }
exit $fail
