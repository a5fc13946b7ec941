#!/bin/bash
# The command `csfcal sessions` prints to continue an unfinished observer session runs as
# printed: it names the display profile the session was measured with (a resume without it is
# refused), found through the display session that wrote the profile.
set -u
exe=$(realpath "$1")
fail=0
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
cd "$d" || exit 1
export XDG_DATA_HOME="$d/data" XDG_CONFIG_HOME="$d/config" EGL_PLATFORM=surfaceless
"$exe" display calibrate --photometer sim:display=lcd --store s.sqlite --out lcd.profile --quiet 2>/dev/null \
  || { echo "display calibrate failed"; exit 1; }
# An observer session stopped by SIGTERM after a few stored trials is left paused.
"$exe" observer calibrate --headless --observer sim --store s.sqlite --profile lcd.profile --trials 200 \
  --render-every -1 --quiet --out me.csflut 2>term.err &
pid=$!
for _ in $(seq 600); do
  n=$(sqlite3 s.sqlite "select count(*) from trials where session_id = 2" 2>/dev/null || echo 0)
  [ "${n:-0}" -ge 3 ] && break
  sleep 0.1
done
kill -TERM "$pid"
wait "$pid"
"$exe" sessions --store s.sqlite >list.out 2>&1
hint=$(sed -n 's/^ *2 (observer): //p' list.out)
[ -n "$hint" ] || { echo "no resume hint for session 2: $(cat list.out)"; exit 1; }
case "$hint" in
  *"--profile lcd.profile"*) ;;
  *) echo "resume hint leaves out the profile: $hint"; fail=1 ;;
esac
# The hint as printed, with the csfcal under test for "csfcal".
eval "${hint/#csfcal/\"\$exe\"} --quiet" >run.out 2>&1
rc=$?
[ "$rc" -eq 0 ] || { echo "the printed hint failed (exit $rc): $hint"; cat run.out; fail=1; }
[ -s FILE.csflut ] || { echo "the printed hint wrote no table"; fail=1; }
"$exe" sessions show 2 --store s.sqlite | grep -q "state *finished" || { echo "session 2 not finished"; fail=1; }
exit $fail
