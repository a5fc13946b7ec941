#!/bin/bash
# csfcal stimulus show in a real GLFW fullscreen window on a private Xvfb, checked from screenshots
# (xwd -root, read by tests/emu/xwd_tool.py, converted to PNG and fitted by show_shot_fit through
# the simulated LCD the frame was drawn for and the station geometry):
#   1. the Gabor on screen has the Michelson contrast and the spatial frequency that were asked,
#      and those stimulus check --json measures offscreen for the same settings: contrast within
#      3 %, frequency within 1 % (the tolerances the check's own tests hold it to);
#   2. Right steps the frequency an octave: the measured frequency doubles, the caption changes;
#   3. a step past the local Nyquist limit is not taken (the measured frequency stays) and the
#      caption says why where it can be read: the reason, not the values, leads the line;
#   4. q quits; --json reports the last settings and the refusal.
# With CSFCAL_SHOW_PNG=FILE the first screenshot is also written there as a PNG (how
# docs/img/stimulus-show.png is made). $1 = csfcal, $2 = show_shot_fit, $3 = tests/emu/xwd_tool.py.
# Skips (77) without Xvfb, xdotool or xwd. Every wait has a timeout.
set -u
CSFCAL="$1" FIT="$2" XWDTOOL="$3"
. "$(dirname "$0")/../xvfb_lib.sh"
xvfb_need Xvfb xdotool xwd
unset EGL_PLATFORM WAYLAND_DISPLAY
xvfb_scratch showx CPID
die() { echo "FAIL: $*"; [ -s "$T/show.err" ] && tail -n 20 "$T/show.err"; exit 1; }
# within A B REL: |A / B - 1| <= REL
within() { awk -v a="$1" -v b="$2" -v r="$3" 'BEGIN { d = a / b - 1; if (d < 0) d = -d; exit !(d <= r) }'; }

W=640 H=360
xvfb_start "$W" "$H"

MM_W=531 MM_H=299 DIST=570 FREQ=1 ECC=3 CONTRAST=0.3 SIGMA=1
SET=(--screen-px ${W}x${H} --screen-mm ${MM_W}x${MM_H} --distance-mm $DIST --photometer sim:display=lcd
     --ecc $ECC --contrast $CONTRAST --sigma $SIGMA --seed 3)

# the same settings measured offscreen by stimulus check
EGL_PLATFORM=surfaceless "$CSFCAL" stimulus check --headless --freq $FREQ --levels 0 --frames 8 --json "${SET[@]}" \
    >"$T/check.json" 2>"$T/check.err" || die "stimulus check failed: $(cat "$T/check.err")"
CHECK_C=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["measured"]["contrast"])' "$T/check.json")
CHECK_F=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["measured"]["freq_cpd"])' "$T/check.json")

"$CSFCAL" stimulus show --freq $FREQ --json "${SET[@]}" >"$T/show.json" 2>"$T/show.err" &
CPID=$!
wait_until 30 bash -c "xdotool search --onlyvisible --name '^csfcal\$' >/dev/null 2>&1" || die "no csfcal window within 30 s"
xdotool mousemove $((W / 2)) $((H / 2)) # no window manager: keyboard focus follows the pointer

shot() { xwd -root -silent >"$T/$1.xwd" && python3 "$XWDTOOL" png "$T/$1.xwd" "$T/$1.png" || die "screenshot $1"; }
# shot_when NAME CHECK ARGS...: screenshots NAME until xwd_tool.py CHECK NAME.xwd ARGS... passes
# (20 s): the caption follows a key once the new frame has been measured, later under load
shot_when() {
    local name="$1" what="$2" end=$((SECONDS + 20)); shift 2
    while :; do
        xwd -root -silent >"$T/$name.xwd" || die "screenshot $name"
        python3 "$XWDTOOL" "$what" "$T/$name.xwd" "$@" >/dev/null && break
        [ $SECONDS -ge $end ] && die "screenshot $name: no $what $* within 20 s"
        sleep 0.3
    done
    python3 "$XWDTOOL" png "$T/$name.xwd" "$T/$name.png" || die "screenshot $name"
}
# fit NAME FREQ_ASKED: "contrast C freq_cpd F mean_cdm2 M" of the Gabor in screenshot NAME
fit() { "$FIT" "$T/$1.png" $MM_W $MM_H $DIST "$2" $ECC 0 $SIGMA lcd || die "fit of $1"; }
field() { awk -v k="$1" '{ for (i = 1; i < NF; i++) if ($i == k) print $(i + 1) }' <<<"$2"; }

# 1. the first frame: as asked, and as stimulus check measures it (once its caption is up)
shot_when one caption
[ -n "${CSFCAL_SHOW_PNG:-}" ] && cp "$T/one.png" "$CSFCAL_SHOW_PNG"
R=$(fit one $FREQ); echo "screenshot 1: $R (stimulus check: contrast $CHECK_C, $CHECK_F cpd)"
check "window: contrast within 3 % of the asked $CONTRAST" within "$(field contrast "$R")" $CONTRAST 0.03
check "window: contrast within 3 % of stimulus check's $CHECK_C" within "$(field contrast "$R")" "$CHECK_C" 0.03
check "window: frequency within 1 % of the asked $FREQ cpd" within "$(field freq_cpd "$R")" $FREQ 0.01
check "window: frequency within 1 % of stimulus check's $CHECK_F cpd" within "$(field freq_cpd "$R")" "$CHECK_F" 0.01
check "window: a caption in the top rows" python3 "$XWDTOOL" caption "$T/one.xwd"

# 2. Right: one octave up, measured on the screen, and the caption follows
xdotool key Right
shot_when two captiondiff "$T/one.xwd" 1
R=$(fit two $((2 * FREQ))); echo "screenshot 2: $R"
check "Right: the measured frequency doubles to $((2 * FREQ)) cpd (within 1 %)" within "$(field freq_cpd "$R")" $((2 * FREQ)) 0.01
check "Right: contrast still within 3 %" within "$(field contrast "$R")" $CONTRAST 0.03
check "Right: the caption changed" python3 "$XWDTOOL" captiondiff "$T/one.xwd" "$T/two.xwd" 1

# 3. up to 4 cpd, then a step to 8 cpd: above the Nyquist limit here (about 6 cpd), not taken
xdotool key Right
shot_when three captiondiff "$T/two.xwd" 1
xdotool key Right
shot_when four captiondiff "$T/three.xwd" 1
R=$(fit four $((4 * FREQ))); echo "screenshot 4 (after the refused step): $R"
check "past the limit: the frequency stays at $((4 * FREQ)) cpd (within 1 %)" within "$(field freq_cpd "$R")" $((4 * FREQ)) 0.01
# the reason must be readable: the caption's text changes over at least half the screen's width
check "past the limit: the caption says why, in view" python3 "$XWDTOOL" captiondiff "$T/three.xwd" "$T/four.xwd" $((W / 2))

# 4. q quits and reports
xdotool key q
wait_until 30 bash -c "! kill -0 $CPID 2>/dev/null" || die "show did not quit on q"
wait "$CPID"; RC=$?; CPID=""
check "q: exit 0 ($RC)" test "$RC" = 0
check "q: --json has the last settings (4 cpd) and the Nyquist refusal" python3 -c '
import json, sys; j = json.load(open(sys.argv[1]))
sys.exit(0 if j["freq_cpd"] == 4 and "Nyquist limit" in j["note"] else 1)' "$T/show.json"
[ $fail = 0 ] || { echo "--- show.err"; tail -n 20 "$T/show.err"; cat "$T/show.json"; }
exit $fail
