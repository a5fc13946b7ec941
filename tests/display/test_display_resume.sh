#!/bin/sh
# A rendered display calibration (patches drawn through the presenter, the simulator reading the
# rendered frames) stopped at several points -- instrument faults in the warm-up, the dark and
# white readings, the grey and the channel sweeps, the spot checks after them (readings 56-72 of
# 72), and a SIGKILL -- and resumed without the fault makes the uninterrupted session's profile:
# the same readings (store) and the same model.
set -u
exe="$1"
fail=0
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
export XDG_CONFIG_HOME="$t/cfg" XDG_DATA_HOME="$t/data"
ph="sim:display=lcd,integration_s=0.1"
common="--seed 3 --render-width 64 --quiet"
"$exe" display calibrate --photometer "$ph" $common --store "$t/ref.sqlite" --out "$t/ref.profile" 2>"$t/e" \
  || { echo "reference calibration failed: $(cat "$t/e")"; exit 1; }
# the readings that count, in order (failed attempts left out), and the profile without its time stamp
readings() {
  python3 - "$1" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
for row in db.execute("select channel, drive01, lum_cdm2, t_s, status from readings where status in ('ok', 'too_dark') order by seq"):
    print(repr(row))
PY
}
model() { grep -v '^created_utc' "$1"; }
readings "$t/ref.sqlite" >"$t/ref.readings"
compare() { # $1: label, $2: store, $3: profile
  readings "$2" >"$t/got.readings"
  cmp -s "$t/ref.readings" "$t/got.readings" \
    || { echo "$1: readings differ ($(wc -l <"$t/ref.readings") vs $(wc -l <"$t/got.readings"))"; \
         diff "$t/ref.readings" "$t/got.readings" | head -4; fail=1; }
  model "$t/ref.profile" >"$t/a"; model "$3" >"$t/b"
  cmp -s "$t/a" "$t/b" || { echo "$1: profile differs"; diff "$t/a" "$t/b" | head -6; fail=1; }
}
for f in timeout@4 garbage@15 unplug@22 timeout@40 unplug@46 timeout@62 garbage@68; do
  rm -f "$t/f.sqlite" "$t/f.profile"
  "$exe" display calibrate --photometer "$ph,fault=$f" $common --store "$t/f.sqlite" --out "$t/f.profile" 2>"$t/e" \
    && { echo "$f: no fault"; fail=1; continue; }
  "$exe" display calibrate --photometer "$ph" --resume 1 --render-width 64 --quiet --store "$t/f.sqlite" \
    --out "$t/f.profile" 2>"$t/e" || { echo "$f: resume failed: $(cat "$t/e")"; fail=1; continue; }
  compare "$f" "$t/f.sqlite" "$t/f.profile"
done
# SIGKILL in the middle of the sweeps, then resume (the default integration time: 30 frames a
# reading, slow enough to land the kill)
ph="sim:display=lcd"
common="--seed 4 --quiet"
"$exe" display calibrate --photometer "$ph" $common --store "$t/ref2.sqlite" --out "$t/ref.profile" 2>"$t/e" \
  || { echo "reference calibration failed: $(cat "$t/e")"; exit 1; }
readings "$t/ref2.sqlite" >"$t/ref.readings"
rm -f "$t/k.sqlite" "$t/k.profile"
"$exe" display calibrate --photometer "$ph" $common --store "$t/k.sqlite" --out "$t/k.profile" 2>/dev/null &
pid=$!
n=0
c=0
while [ "$n" -lt 400 ]; do
  c=$(python3 -c 'import sqlite3,sys
try: print(sqlite3.connect(sys.argv[1]).execute("select count(*) from readings").fetchone()[0])
except Exception: print(0)' "$t/k.sqlite" 2>/dev/null)
  [ "${c:-0}" -ge 30 ] && break
  sleep 0.02
  n=$((n + 1))
done
kill -KILL "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
if [ -e "$t/k.profile" ]; then
  echo "note: the session finished before the kill; nothing to resume"
else
  "$exe" display calibrate --photometer "$ph" --resume 1 --quiet --store "$t/k.sqlite" \
    --out "$t/k.profile" 2>"$t/e" || { echo "SIGKILL: resume failed: $(cat "$t/e")"; fail=1; }
  compare "SIGKILL after $c readings" "$t/k.sqlite" "$t/k.profile"
fi
exit $fail
