#!/bin/sh
# What the command line used to accept silently is refused with exit 2 and a message naming the
# item: a key given twice or an empty item in a simulated device's spec, --monitor for a session
# drawn offscreen, an empty --set store=. A store folder that does not exist is created only with
# a note saying so. `csfcal devices` says --headless was asked for only when it was.
set -u
exe="$1"
fail=0
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
export XDG_DATA_HOME="$d/data" XDG_CONFIG_HOME="$d/config" EGL_PLATFORM=surfaceless

# expect_refused NAME TEXT ARGS...: exit 2, TEXT on stderr, nothing stored.
expect_refused() {
  name=$1 text=$2
  shift 2
  "$exe" "$@" >"$d/out" 2>"$d/err"
  rc=$?
  [ "$rc" -eq 2 ] || { echo "$name: exit $rc, expected 2 ($(cat "$d/err"))"; fail=1; }
  grep -qF -- "$text" "$d/err" || { echo "$name: expected '$text', got: $(cat "$d/err")"; fail=1; }
  [ ! -e "$d/x.csflut" ] && [ ! -e "$d/x.profile" ] || { echo "$name: an output was written"; fail=1; }
  if [ -e "$d/s.sqlite" ] && [ "$(sqlite3 "$d/s.sqlite" 'select count(*) from sessions')" != 0 ]; then
    echo "$name: a session was stored"; fail=1
  fi
  rm -f "$d/s.sqlite" "$d/x.csflut" "$d/x.profile"
}
obs="observer calibrate --headless --store $d/s.sqlite --out $d/x.csflut --trials 2 --freqs 1 --eccs 0"
expect_refused "key twice" "--observer: key 'smax' given twice (items 1 and 2 of 'smax=250,smax=300')" \
  $obs --observer sim:smax=250,smax=300
expect_refused "empty item" "--observer: item 2 of 'smax=250,,fmax=3' is empty" \
  $obs --observer sim:smax=250,,fmax=3
expect_refused "trailing comma" "--observer: item 2 of 'smax=250,' is empty" $obs --observer sim:smax=250,
expect_refused "photometer key twice" "sim photometer: key 'noise' given twice (items 1 and 2" \
  display calibrate --photometer sim:noise=0.01,noise=0.02 --store "$d/s.sqlite" --out "$d/x.profile"
expect_refused "display key twice" "sim photometer: key 'gamma' given twice (items 2 and 3" \
  display calibrate --photometer sim:display=lcd,gamma=2.2,gamma=2.4 --store "$d/s.sqlite" --out "$d/x.profile"
expect_refused "set store empty" "--set store=: empty path (give a file, or leave it out for the default $d/data/csfcal/csfcal.sqlite)" \
  observer calibrate --headless --set store= --out "$d/x.csflut" --trials 2 --freqs 1 --eccs 0
[ ! -e "$d/data" ] || { echo "--set store=: the default store's folder was created"; fail=1; }
expect_refused "set display_profile empty" "--set display_profile=: empty path" $obs --set display_profile=
expect_refused "monitor headless" "--monitor 1: this session draws offscreen because --headless was given" \
  $obs --monitor 1
expect_refused "monitor by set" "--monitor 2: this session draws offscreen because --headless was given" \
  $obs --set monitor=2
DISPLAY='' WAYLAND_DISPLAY='' expect_refused "monitor without display" "because there is no display" \
  observer calibrate --store "$d/s.sqlite" --out "$d/x.csflut" --trials 2 --freqs 1 --eccs 0 --observer sim --monitor 1
expect_refused "monitor study" "study run: --monitor 1: this session draws offscreen" \
  study run "$(dirname "$0")/../../examples/studies/yes_no.conf" --participant P1 --headless --store "$d/s.sqlite" \
  --monitor 1
expect_refused "monitor png" "stimulus show: --monitor 1: this session draws offscreen because --png writes files" \
  stimulus show --png "$d/x.png" --freq 2 --monitor 1
expect_refused "distance over the commands' limit" "viewing_distance_mm = 15000 is out of range (allowed 100 to 10000 mm)" \
  devices --headless --set viewing_distance_mm=15000

# A store whose folder does not exist: the folder is made, and stderr says so.
# (LeakSanitizer's tracer can crash stopping llvmpipe's threads at exit; leaks are not the point here)
ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" "$exe" observer calibrate --headless --observer sim \
  --store "$d/new/deeper/s.sqlite" --out "$d/x.csflut" --trials 2 --freqs 1 --eccs 0 >/dev/null 2>"$d/err"
rc=$?
[ "$rc" -eq 0 ] || { echo "new store folder: exit $rc: $(cat "$d/err")"; fail=1; }
grep -qF "note: the store's folder $d/new/deeper did not exist; created it" "$d/err" \
  || { echo "new store folder: no note: $(cat "$d/err")"; fail=1; }
"$exe" sessions --store "$d/new/deeper/s.sqlite" >/dev/null 2>"$d/err"
! grep -q "did not exist" "$d/err" || { echo "existing store folder: a note anyway"; fail=1; }

# devices: the reason it lists no monitors is the true one.
DISPLAY= WAYLAND_DISPLAY= "$exe" devices >"$d/out" 2>&1
grep -q -- "--headless was asked for" "$d/out" && { echo "devices says --headless was asked for: $(grep display "$d/out")"; fail=1; }
grep -q "no window system reachable" "$d/out" || { echo "devices: no reason for no monitors: $(cat "$d/out")"; fail=1; }
"$exe" devices --headless >"$d/out" 2>&1
grep -q -- "--headless was asked for" "$d/out" || { echo "devices --headless: $(grep display "$d/out")"; fail=1; }
exit $fail
