#!/bin/sh
# csfcal display from the shell: calibrate into a store, info, verify, every export, a fault that
# keeps its readings and a --resume that finishes, and clear refusals of bad input.
set -u
exe="$1"
data="$2"
fail=0
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
db="$t/s.sqlite"
# no station configuration of the machine's user leaks in
export XDG_CONFIG_HOME="$t/cfg" XDG_DATA_HOME="$t/data"
"$exe" display calibrate --photometer sim:display=lcd --seed 1 --store "$db" --out "$t/lcd.profile" --quiet \
  || { echo "calibrate failed"; fail=1; }
head -1 "$t/lcd.profile" | grep -q '^csfcal-display-profile 1$' || { echo "profile header"; fail=1; }
"$exe" display info "$t/lcd.profile" > "$t/info" || { echo "info failed"; fail=1; }
grep -q '^channels: r, g, b' "$t/info" || { echo "info: $(cat "$t/info")"; fail=1; }
"$exe" display verify "$t/lcd.profile" --photometer sim:display=lcd --seed 9 > "$t/v" || { echo "verify of a fresh profile failed: $(cat "$t/v")"; fail=1; }
grep -q ': ok' "$t/v" || { echo "verify: $(cat "$t/v")"; fail=1; }
# a different monitor (brighter) is reported as drifted, exit 1
"$exe" display verify "$t/lcd.profile" --photometer sim:display=lcd,lmax=200 > "$t/v" && { echo "drift not detected"; fail=1; }
grep -q 'DRIFTED' "$t/v" || { echo "verify drift: $(cat "$t/v")"; fail=1; }
# old profiles are flagged
sed 's/^created_utc = .*/created_utc = 2020-01-01T00:00:00Z/' "$t/lcd.profile" > "$t/old.profile"
"$exe" display info "$t/old.profile" --set profile_max_age_days=30 2>"$t/e" >/dev/null
grep -q 'days old' "$t/e" || { echo "age not flagged: $(cat "$t/e")"; fail=1; }
for f in clf ctf cube icc ocio; do
  "$exe" display export "$t/lcd.profile" --format $f -o "$t/out.$f" >/dev/null || { echo "export $f failed"; fail=1; }
  [ -s "$t/out.$f" ] || { echo "export $f empty"; fail=1; }
done
[ -s "$t/out.clf" ] && grep -q 'ProcessList' "$t/out.clf" || { echo "clf content"; fail=1; }
grep -q 'LUT_1D_SIZE' "$t/out.cube" || { echo "cube is not 1-D: $(head -5 "$t/out.cube")"; fail=1; }
grep -q 'csfcal_display' "$t/out.ocio" || { echo "ocio config content"; fail=1; }
# fault: clear message, readings kept, resume completes
"$exe" display calibrate --photometer sim:display=crt,fault=unplug@30 --store "$db" --out "$t/crt.profile" --quiet 2>"$t/e"
rc=$?
[ "$rc" -eq 1 ] || { echo "fault exit $rc"; fail=1; }
grep -q 'disconnected' "$t/e" || { echo "fault message: $(cat "$t/e")"; fail=1; }
grep -q 'readings kept in session' "$t/e" || { echo "no resume hint: $(cat "$t/e")"; fail=1; }
# the hint names the photometer that was used, not a placeholder (here, and in sessions list)
grep -q -- '--photometer sim:display=crt,fault=unplug@30 ' "$t/e" || { echo "hint lacks the spec: $(cat "$t/e")"; fail=1; }
"$exe" sessions list --store "$db" >"$t/l" 2>&1
grep -q -- '--photometer sim:display=crt,fault=unplug@30 ' "$t/l" || { echo "list hint lacks the spec: $(cat "$t/l")"; fail=1; }
[ -e "$t/crt.profile" ] && { echo "profile written despite fault"; fail=1; }
sid=$(sed -n 's/.*--resume \([0-9]*\).*/\1/p' "$t/e" | head -1)
"$exe" display calibrate --resume "$sid" --photometer sim:display=crt --store "$db" --out "$t/crt.profile" --quiet 2>"$t/e2" \
  || { echo "resume failed: $(cat "$t/e2")"; fail=1; }
# the instrument spec changed (the fault is gone): said, not refused
grep -q "was measured on 'sim:display=crt,fault=unplug@30'" "$t/e2" || { echo "no spec-change warning: $(cat "$t/e2")"; fail=1; }
[ -s "$t/crt.profile" ] || { echo "no profile after resume"; fail=1; }
# an --out that cannot be written is refused before the first reading: exit 2, no session stored
"$exe" display calibrate --photometer sim:display=lcd --store "$t/noout.sqlite" --out "$t/missing/x.profile" --quiet 2>"$t/e4"
rc=$?
[ "$rc" -eq 2 ] || { echo "unwritable --out: exit $rc, want 2"; fail=1; }
grep -q 'missing.*No such file or directory' "$t/e4" || { echo "unwritable --out message: $(cat "$t/e4")"; fail=1; }
[ ! -e "$t/noout.sqlite" ] || [ "$(sqlite3 "$t/noout.sqlite" "SELECT count(*) FROM sessions")" = 0 ] \
  || { echo "unwritable --out: a session was started"; fail=1; }
# damaged stored settings (a value no session could have): refused once, exit 2, named with its
# range, the session marked aborted and its readings kept; no resume hint (it would fail forever)
db3="$t/damaged.sqlite"
"$exe" display calibrate --photometer sim:display=lcd,fault=unplug@20 --store "$db3" --out "$t/d.profile" --quiet 2>/dev/null
sqlite3 "$db3" "UPDATE sessions SET settings_json = replace(settings_json, '\"budget\":', '\"budget\":1e300,\"x\":') WHERE id = 1"
sqlite3 "$db3" "SELECT settings_json FROM sessions WHERE id = 1" | python3 -c 'import json,sys; assert json.load(sys.stdin)["budget"] == 1e300' \
  || { echo "could not damage the stored settings"; fail=1; }
kept=$(sqlite3 "$db3" "SELECT count(*) FROM readings WHERE session_id = 1")
"$exe" display calibrate --photometer sim:display=lcd --resume 1 --store "$db3" --out "$t/d.profile" --quiet 2>"$t/e3"
rc=$?
[ "$rc" -eq 2 ] || { echo "damaged settings: exit $rc, want 2: $(cat "$t/e3")"; fail=1; }
grep -q 'budget = 1e+300 is not a whole number from 8 to 4096' "$t/e3" || { echo "damaged settings message: $(cat "$t/e3")"; fail=1; }
grep -q 'finish it with' "$t/e3" && { echo "resume hint for a session that cannot resume"; fail=1; }
[ "$(sqlite3 "$db3" "SELECT state FROM sessions WHERE id = 1")" = aborted ] || { echo "damaged session not aborted"; fail=1; }
[ "$(sqlite3 "$db3" "SELECT count(*) FROM readings WHERE session_id = 1")" = "$kept" ] && [ "$kept" -gt 0 ] \
  || { echo "readings lost: $kept before"; fail=1; }
# an aborted session stays aborted: a second resume is refused (before, it was taken back to running)
"$exe" display calibrate --photometer sim:display=lcd --resume 1 --store "$db3" --out "$t/d.profile" --quiet 2>"$t/e3"
rc=$?
[ "$rc" -eq 2 ] && grep -q 'session 1 was aborted; only running or paused display sessions' "$t/e3" \
  || { echo "resume of an aborted session: exit $rc: $(cat "$t/e3")"; fail=1; }
[ "$(sqlite3 "$db3" "SELECT state FROM sessions WHERE id = 1")" = aborted ] || { echo "aborted session resumed"; fail=1; }
db4="$t/closed.sqlite"
"$exe" display calibrate --photometer sim:display=lcd,fault=unplug@20 --store "$db4" --out "$t/c.profile" --quiet 2>/dev/null
"$exe" sessions abort 1 --store "$db4" >/dev/null 2>&1 || { echo "sessions abort failed"; fail=1; }
"$exe" display calibrate --photometer sim:display=lcd --resume 1 --store "$db4" --out "$t/c.profile" --quiet 2>"$t/e3"
rc=$?
[ "$rc" -eq 2 ] && grep -q 'was aborted' "$t/e3" && [ ! -e "$t/c.profile" ] \
  && [ "$(sqlite3 "$db4" "SELECT state FROM sessions WHERE id = 1")" = aborted ] \
  || { echo "resume after sessions abort: exit $rc: $(cat "$t/e3")"; fail=1; }
# CSV display
"$exe" display calibrate --photometer "sim:display=file=$data/kink.csv" --store "$db" --out "$t/k.profile" --quiet \
  || { echo "csv calibrate failed"; fail=1; }
# refusals
"$exe" display calibrate --photometer sim --store "$db" 2>"$t/e" && { echo "missing --out accepted"; fail=1; }
grep -q -- '--out PROFILE is required' "$t/e" || { echo "msg: $(cat "$t/e")"; fail=1; }
"$exe" display calibrate --photometer sim:noise=5 --store "$db" --out "$t/x" 2>"$t/e" && { echo "noise=5 accepted"; fail=1; }
grep -q 'out of range' "$t/e" || { echo "msg: $(cat "$t/e")"; fail=1; }
"$exe" display calibrate --photometer sim --budget 2 --store "$db" --out "$t/x" 2>"$t/e"
[ $? -eq 2 ] || { echo "budget 2 accepted"; fail=1; }
"$exe" display export "$t/lcd.profile" --format tiff 2>"$t/e" && { echo "tiff accepted"; fail=1; }
grep -q "unknown format 'tiff'" "$t/e" || { echo "msg: $(cat "$t/e")"; fail=1; }
printf 'csfcal-display-profile 1\n[curve grey]\ntransform_gamma = 2\ndrive01,lum_cdm2\n0,5\n1,2\n' > "$t/bad.profile"
"$exe" display info "$t/bad.profile" 2>"$t/e" && { echo "bad profile accepted"; fail=1; }
grep -q "bad.profile:6: knots must rise" "$t/e" || { echo "msg: $(cat "$t/e")"; fail=1; }
"$exe" display frobnicate 2>/dev/null && { echo "unknown subcommand accepted"; fail=1; }
# --json: every display command that takes it prints one JSON object
jq_py='import json,sys; d=json.load(sys.stdin); print(d[sys.argv[1]])'
"$exe" display calibrate --photometer sim:display=lcd --seed 2 --store "$db" --out "$t/j.profile" --no-render --json \
  >"$t/j" 2>"$t/e" || { echo "calibrate --json failed: $(cat "$t/e")"; fail=1; }
python3 -c "$jq_py" profile_id <"$t/j" >/dev/null || { echo "calibrate --json: $(cat "$t/j")"; fail=1; }
[ "$(python3 -c "$jq_py" readings <"$t/j")" -gt 40 ] || { echo "calibrate --json readings: $(cat "$t/j")"; fail=1; }
"$exe" display verify "$t/j.profile" --photometer sim:display=lcd --no-render --channels --json >"$t/j" 2>"$t/e" \
  || { echo "verify --json failed: $(cat "$t/j") $(cat "$t/e")"; fail=1; }
[ "$(python3 -c "$jq_py" verdict <"$t/j")" = ok ] || { echo "verify --json: $(cat "$t/j")"; fail=1; }
python3 -c 'import json,sys; d=json.load(sys.stdin); assert set(d["curves"]) == {"r","g","b","grey"}, d' <"$t/j" \
  || { echo "verify --channels --json curves: $(cat "$t/j")"; fail=1; }
"$exe" display info "$t/j.profile" --json >"$t/j" || { echo "info --json failed"; fail=1; }
python3 -c "$jq_py" grey_drive_for_rel_lum <"$t/j" >/dev/null || { echo "info --json: $(cat "$t/j")"; fail=1; }
"$exe" display export "$t/j.profile" --format cube -o "$t/j.cube" --json >"$t/jx" || { echo "export --json failed"; fail=1; }
python3 -c "$jq_py" wrote <"$t/jx" >/dev/null || { echo "export --json: $(cat "$t/jx")"; fail=1; }
# "% of white" means one thing in info and the exports: the .cube (drive -> relative luminance)
# gives 0.1, 0.5, 0.9 at the drives info names for 10/50/90 %
python3 - "$t/j" "$t/j.cube" <<'PY' || { echo "info and cube disagree on % of white"; fail=1; }
import json, sys
info = json.load(open(sys.argv[1]))
rows = [l.split() for l in open(sys.argv[2]) if l.strip() and l.split()[0].replace('.', '').replace('-', '').replace('e', '').isdigit()]
ys = [float(r[0]) for r in rows if len(r) == 3]
n = len(ys)
for key, want in (("0.1", 0.1), ("0.5", 0.5), ("0.9", 0.9)):
    d = info["grey_drive_for_rel_lum"][key] * (n - 1)
    i = min(int(d), n - 2)
    y = ys[i] + (ys[i + 1] - ys[i]) * (d - i)
    assert abs(y - want) < 2e-4, (key, y, n)
PY
# a --no-channels session resumed without the option is reported as what it is (grey only)
"$exe" display calibrate --photometer sim:display=lcd,fault=unplug@30 --no-channels --no-render --store "$t/nc.sqlite" \
  --out "$t/nc.profile" --quiet 2>/dev/null
"$exe" display calibrate --photometer sim:display=lcd --resume 1 --no-render --store "$t/nc.sqlite" --out "$t/nc.profile" \
  --json >"$t/j" 2>/dev/null || { echo "no-channels resume failed"; fail=1; }
python3 -c 'import json,sys; d=json.load(sys.stdin); assert list(d["error_indicator_rel"]) == ["grey"] and d["additivity_error"] is None, d' \
  <"$t/j" || { echo "no-channels resume --json: $(cat "$t/j")"; fail=1; }
# no photometer named: refused with how to choose one (no silent simulator)
"$exe" display calibrate --store "$db" --out "$t/x.profile" 2>"$t/e"
[ $? -eq 2 ] || { echo "calibrate without --photometer not refused"; fail=1; }
grep -q -- '--photometer SPEC' "$t/e" && grep -q 'sim:display=lcd' "$t/e" || { echo "msg: $(cat "$t/e")"; fail=1; }
[ -e "$t/x.profile" ] && { echo "profile written without a photometer"; fail=1; }
"$exe" display verify "$t/lcd.profile" >"$t/v" 2>"$t/e"
[ $? -eq 2 ] || { echo "verify without --photometer not refused: $(cat "$t/v")"; fail=1; }
grep -q ': ok' "$t/v" && { echo "verify without a photometer says ok"; fail=1; }
# a simulator is announced on stderr, also when it comes from the station configuration
mkdir -p "$t/cfg/csfcal"
printf 'photometer = sim:display=lcd\n' > "$t/cfg/csfcal/station.conf"
"$exe" display verify "$t/lcd.profile" --no-render >/dev/null 2>"$t/e" || { echo "verify with configured sim: $(cat "$t/e")"; fail=1; }
grep -q "SIMULATOR" "$t/e" && grep -q "station.conf" "$t/e" || { echo "configured simulator not announced: $(cat "$t/e")"; fail=1; }
rm -f "$t/cfg/csfcal/station.conf"
# --config DIR and --store "" are refused, not replaced by defaults
"$exe" display info "$t/lcd.profile" --config "$t" >/dev/null 2>"$t/e"
[ $? -eq 2 ] || { echo "--config DIR accepted"; fail=1; }
grep -q 'is a folder' "$t/e" || { echo "msg: $(cat "$t/e")"; fail=1; }
"$exe" display calibrate --photometer sim --store "" --out "$t/x.profile" 2>"$t/e"
[ $? -eq 2 ] || { echo "--store '' accepted"; fail=1; }
grep -q 'empty path' "$t/e" || { echo "msg: $(cat "$t/e")"; fail=1; }
# an option of another subcommand is refused, named, not ignored
"$exe" display verify "$t/lcd.profile" --photometer sim --budget 10 >/dev/null 2>"$t/e"
[ $? -eq 2 ] && grep -q -- '--budget does not apply to verify' "$t/e" || { echo "verify --budget: $(cat "$t/e")"; fail=1; }
"$exe" display calibrate --photometer sim --tolerance 0.1 --store "$db" --out "$t/x.profile" 2>"$t/e"
[ $? -eq 2 ] && grep -q -- '--tolerance does not apply to calibrate' "$t/e" || { echo "calibrate --tolerance: $(cat "$t/e")"; fail=1; }
"$exe" display info "$t/lcd.profile" -o "$t/x" >/dev/null 2>"$t/e"
[ $? -eq 2 ] && grep -q -- '--out does not apply to info' "$t/e" || { echo "info -o: $(cat "$t/e")"; fail=1; }
# a patch smaller than the meter's field (the simulator declares an LS-100's 1 deg, 2 deg with the
# aiming margin) is refused before any reading, naming the patch in deg and mm and the limit
"$exe" display calibrate --photometer sim:display=lcd --patch-deg 1.5 --store "$t/small.sqlite" --out "$t/small.profile" \
  2>"$t/e" >/dev/null
[ $? -eq 2 ] || { echo "small patch: exit status"; fail=1; }
grep -q '1.5 deg patch (14.9 mm at 570 mm) is too small' "$t/e" && grep -q 'at least 2 deg' "$t/e" \
  || { echo "small patch: $(cat "$t/e")"; fail=1; }
[ -e "$t/small.profile" ] && { echo "small patch: a profile was written"; fail=1; }
"$exe" display verify "$t/lcd.profile" --photometer sim:display=lcd --patch-deg 1 >/dev/null 2>"$t/e"
[ $? -eq 2 ] && grep -q 'too small for the meter' "$t/e" || { echo "verify small patch: $(cat "$t/e")"; fail=1; }
"$exe" display verify "$t/lcd.profile" --photometer sim:display=lcd --patch-deg 25 --render-width 32 >/dev/null 2>"$t/e"
grep -q 'warning: photometer sim: the 25 deg patch' "$t/e" || { echo "large patch: $(cat "$t/e")"; fail=1; }
# --monitor with the simulated photometer is refused, not ignored: its patches are drawn offscreen
"$exe" display calibrate --store "$t/mon.sqlite" --out "$t/mon.profile" --photometer sim:display=lcd --monitor 1 \
  >/dev/null 2>"$t/e"
[ $? -eq 2 ] && grep -q -- '--monitor 1: this session draws offscreen because the simulated photometer' "$t/e" \
  || { echo "calibrate --monitor with the simulator: $(cat "$t/e")"; fail=1; }
"$exe" display verify "$t/lcd.profile" --photometer sim:display=lcd --monitor 1 >/dev/null 2>"$t/e"
[ $? -eq 2 ] && grep -q -- '--monitor 1: this session draws offscreen because the simulated photometer' "$t/e" \
  || { echo "verify --monitor with the simulator: $(cat "$t/e")"; fail=1; }
[ -e "$t/mon.profile" ] && { echo "--monitor: a profile was written"; fail=1; }
# and the refusal leaves no store file behind (it comes before the store is opened)
[ -e "$t/mon.sqlite" ] && { echo "--monitor: a store file was made before the refusal"; fail=1; }
# --checks: out of range refused; 0 takes none, and the JSON says how many were taken
"$exe" display calibrate --store "$t/chk.sqlite" --out "$t/chk.profile" --photometer sim:display=lcd --checks 65 \
  >/dev/null 2>"$t/e"
[ $? -eq 2 ] && grep -q -- '--checks: 65 is out of range (allowed 0 to 64)' "$t/e" \
  || { echo "--checks 65: $(cat "$t/e")"; fail=1; }
for n in 0 3; do
  "$exe" display calibrate --store "$t/chk.sqlite" --out "$t/chk$n.profile" --photometer sim:display=lcd --checks $n \
    --json 2>/dev/null >"$t/chk$n.json"
  python3 -c 'import json, sys
d = json.load(open(sys.argv[1])); n = int(sys.argv[2])
assert d["check_readings"] == 4 * n, d["check_readings"]
assert (d["check_error_rel"]["grey"] is None) == (n == 0), d["check_error_rel"]' "$t/chk$n.json" $n \
    || { echo "--checks $n: $(head -c 400 "$t/chk$n.json")"; fail=1; }
done
# a LUT's ripple between the sweep's levels: the sweep meets the target at its levels, the checks
# show it is not met, and the warning says more budget would not help (not that it would)
"$exe" display calibrate --store "$t/chk.sqlite" --out "$t/rip.profile" --json \
  --photometer "sim:display=file=$data/heldout_lutwiggle.csv,noise=0.0005" 2>"$t/e" >"$t/rip.json"
python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
assert d["target_met"] is False and d["checks_raised"] is True, d
assert d["check_error_rel"]["grey"] > 0.0025, d["check_error_rel"]' "$t/rip.json" \
  && grep -q 'a larger --budget would not meet it' "$t/e" && ! grep -q 'would meet it' "$t/e" \
  || { echo "ripple between the levels: $(cat "$t/e") $(head -c 300 "$t/rip.json")"; fail=1; }
# verify waits for warm-up: a monitor still warming up is NOT WARM (exit 1), never "ok"
"$exe" display verify "$t/lcd.profile" --photometer sim:display=lcd,warmup_s=120,drift=0.3 --no-render >"$t/v" 2>/dev/null
[ $? -eq 1 ] || { echo "cold monitor: exit status"; fail=1; }
grep -q 'NOT WARM' "$t/v" || { echo "cold monitor: $(cat "$t/v")"; fail=1; }
# a profile id carries no file path of the photometer spec
"$exe" display calibrate --photometer "sim:display=file=$data/kink.csv" --store "$db" --out "$t/k2.profile" --no-render --json \
  >"$t/j" 2>/dev/null || { echo "csv calibrate --json failed"; fail=1; }
id=$(python3 -c "$jq_py" profile_id <"$t/j")
case "$id" in */*|*kink*) echo "id carries the path: $id"; fail=1;; esac
[ ${#id} -le 48 ] || { echo "id too long: $id"; fail=1; }
# "too dark" during the dark readings, then --resume without the fault:
# black is the LCD's 0.35 cd/m2, not 0
"$exe" display calibrate --photometer sim:display=lcd,fault=dark@13 --no-render --seed 5 --store "$t/d.sqlite" \
  --out "$t/d.profile" --quiet 2>/dev/null && { echo "dark fault: no error"; fail=1; }
"$exe" display calibrate --photometer sim:display=lcd --no-render --resume 1 --store "$t/d.sqlite" --out "$t/d.profile" \
  --json >"$t/j" 2>/dev/null || { echo "dark fault: resume failed"; fail=1; }
python3 -c 'import json,sys; b=json.load(sys.stdin)["black_cdm2"]; assert abs(b/0.35-1) < 0.02, b' <"$t/j" \
  || { echo "dark fault: resumed black $(cat "$t/j")"; fail=1; }
exit $fail
