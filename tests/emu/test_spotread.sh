#!/bin/sh
# The ArgyllCMS spotread bridge against the stand-in spotread (fake_spotread.c, first on PATH):
# a full display calibration whose profile matches the simulated photometer's on the same LCD
# within +-2 % + 0.01 cd/m2 (the serial meters' stated figure; the stand-in models an exact
# instrument, a real one's accuracy is its own), a meter 5 % off failing that comparison, and
# every failure spotread prints or shows: no instrument, initialisation failure, communication
# problem (unplug), silence (timeout), an unreadable and a cut-short result line, too dark, too
# bright, low battery, a crash, a slow instrument, no spotread on PATH. Each mid-session failure
# names spotread and the problem, keeps the readings, and resumes to a good profile.
#   usage: test_spotread.sh CSFCAL STANDIN_DIR PROFILE_EVAL
set -u
exe=$1 standin=$2 peval=$3
fail=0
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
export XDG_CONFIG_HOME="$t/cfg" XDG_DATA_HOME="$t/data" CSFCAL_SCREEN_MIRROR="$t/screen"
export PATH="$standin:$PATH"
[ "$(command -v spotread)" = "$standin/spotread" ] || { echo "stand-in not first on PATH"; exit 1; }
common="--no-render --warmup-wait 0 --seed 3 --quiet"
within() {
  levels="0 0.0625 0.125 0.1875 0.25 0.3125 0.375 0.4375 0.5 0.5625 0.625 0.6875 0.75 0.8125 0.875 0.9375 1"
  "$peval" "$1" $levels >"$t/pa" && "$peval" "$2" $levels >"$t/pb" || return 2
  python3 - "$t/pa" "$t/pb" <<'PY'
import sys
a = [list(map(float, l.split())) for l in open(sys.argv[1])]
b = [list(map(float, l.split())) for l in open(sys.argv[2])]
pairs = [(a[0][0], b[0][0]), (a[0][1], b[0][1])] + [(x[1], y[1]) for x, y in zip(a[1:], b[1:])]
worst = max(abs(x - y) - (0.02 * y + 0.01) for x, y in pairs)
rel = max(abs(x - y) / y for x, y in pairs if y > 1)
print("largest relative difference above 1 cd/m2: %.4f %%" % (100 * rel))
sys.exit(0 if worst <= 0 else 1)
PY
}
stored() {
  python3 -c 'import sqlite3,sys; print(sqlite3.connect(sys.argv[1]).execute("select count(*) from readings where status=?", (sys.argv[2],)).fetchone()[0])' "$1" "$2"
}
"$exe" display calibrate --photometer sim:display=lcd $common --store "$t/ref.sqlite" --out "$t/ref.profile" 2>"$t/e" \
  || { echo "simulated reference failed: $(cat "$t/e")"; exit 1; }

CSF_FAKE_SPOTREAD=seed=5 "$exe" display calibrate --photometer "spotread:-c 1 -y l" $common --store "$t/c.sqlite" \
  --out "$t/c.profile" 2>"$t/e" || { echo "spotread calibration failed: $(cat "$t/e")"; fail=1; }
r=$(within "$t/c.profile" "$t/ref.profile") || { echo "spotread: profile outside +-2 % + 0.01 cd/m2: $r"; fail=1; }
echo "spotread: $r"
CSF_FAKE_SPOTREAD=gain=1.05 "$exe" display calibrate --photometer spotread $common --store "$t/g.sqlite" \
  --out "$t/g.profile" 2>"$t/e" || { echo "gain 1.05: calibration failed: $(cat "$t/e")"; fail=1; }
within "$t/g.profile" "$t/ref.profile" >/dev/null && { echo "a meter 5 % off passed the accuracy comparison"; fail=1; }

# failures before the first reading: refused with the reason, nothing measured
check_start() { # FAKE_SETTINGS KEYWORD
  CSF_FAKE_SPOTREAD=$1 "$exe" display calibrate --photometer "spotread:start_timeout_s=2" $common --store "$t/n.sqlite" \
    --out "$t/n.profile" 2>"$t/e" && { echo "$1: did not fail"; fail=1; return; }
  grep -q "spotread (ArgyllCMS).*$2" "$t/e" || { echo "$1: message: $(cat "$t/e")"; fail=1; }
  echo "start $1: '$(sed -n 's/^csfcal: display calibrate: //p' "$t/e" | head -1)'"
}
check_start fault=noinst "no instrument detected"
check_start fault=initfail "Instrument initialisation failed"
PATH=/nonexistent-dir "$exe" display calibrate --photometer spotread $common --store "$t/n.sqlite" --out "$t/n.profile" 2>"$t/e"
grep -q "no spotread on PATH: install ArgyllCMS" "$t/e" || { echo "no spotread: $(cat "$t/e")"; fail=1; }
"$exe" display calibrate --photometer "spotread:-O" $common --store "$t/n.sqlite" --out "$t/n.profile" 2>"$t/e"
[ $? -eq 2 ] && grep -q "option -O is not for csfcal" "$t/e" || { echo "-O: $(cat "$t/e")"; fail=1; }

# failures mid-session: message, readings kept, resumable
check_fault() { # FAULT KEYWORD
  rm -f "$t/f.sqlite" "$t/f.profile"
  CSF_FAKE_SPOTREAD="seed=5,fault=$1" "$exe" display calibrate --photometer "spotread:timeout_s=1" $common \
    --store "$t/f.sqlite" --out "$t/f.profile" 2>"$t/e" && { echo "$1: did not fail"; fail=1; return; }
  grep -q "spotread (ArgyllCMS) -e -x" "$t/e" || { echo "$1: message does not name spotread: $(cat "$t/e")"; fail=1; }
  grep -qi "$2" "$t/e" || { echo "$1: message does not say '$2': $(cat "$t/e")"; fail=1; }
  grep -q "readings kept in session 1" "$t/e" || { echo "$1: no resume hint: $(cat "$t/e")"; fail=1; }
  ok=$(stored "$t/f.sqlite" ok)
  [ "$ok" -gt 0 ] || { echo "$1: no reading kept"; fail=1; }
  CSF_FAKE_SPOTREAD=seed=6 "$exe" display calibrate --resume 1 --photometer spotread --warmup-wait 0 --no-render --quiet \
    --store "$t/f.sqlite" --out "$t/f.profile" 2>"$t/e2" || { echo "$1: resume failed: $(cat "$t/e2")"; fail=1; return; }
  within "$t/f.profile" "$t/ref.profile" >/dev/null || { echo "$1: resumed profile outside the accuracy"; fail=1; }
  echo "$1: '$(sed -n 's/^csfcal: display calibrate: //p' "$t/e" | head -1)'; $ok readings kept, resumed"
}
check_fault unplug@30 "communication problem"
check_fault crash@25 "exited with status 3"
check_fault timeout@20 "no answer to a reading within 1.0 s"
check_fault garbage@22 "Result is XYZ: 12.5 nan"
check_fault truncated@33 "cut short"
check_fault dark@14 "Light level is too low"
check_fault over@12 "Too bright"
check_fault battery@10 "Battery too low"
grep -q "reading 10 (" "$t/e" || { echo "battery: the low battery was taken for a dark reading: $(cat "$t/e")"; fail=1; }
# slow: answers late, within the timeout
CSF_FAKE_SPOTREAD=slow=0.02 "$exe" display calibrate --photometer "spotread:timeout_s=2" $common --store "$t/s.sqlite" \
  --out "$t/s.profile" 2>"$t/e" || { echo "slow: failed: $(cat "$t/e")"; fail=1; }
# a too-dark answer near black is a fact about the display, not a fault: an OLED calibrates
CSF_FAKE_SPOTREAD=display=oled "$exe" display calibrate --photometer spotread $common --store "$t/o.sqlite" \
  --out "$t/o.profile" 2>"$t/e" || { echo "oled: failed: $(cat "$t/e")"; fail=1; }
[ "$(stored "$t/o.sqlite" too_dark)" -gt 0 ] || { echo "oled: no too-dark reading at black"; fail=1; }
exit $fail
