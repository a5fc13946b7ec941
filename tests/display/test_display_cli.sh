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
[ -e "$t/crt.profile" ] && { echo "profile written despite fault"; fail=1; }
sid=$(sed -n 's/.*--resume \([0-9]*\).*/\1/p' "$t/e" | head -1)
"$exe" display calibrate --resume "$sid" --photometer sim:display=crt --store "$db" --out "$t/crt.profile" --quiet 2>"$t/e2" \
  || { echo "resume failed: $(cat "$t/e2")"; fail=1; }
# the instrument spec changed (the fault is gone): said, not refused
grep -q "was measured on 'sim:display=crt,fault=unplug@30'" "$t/e2" || { echo "no spec-change warning: $(cat "$t/e2")"; fail=1; }
[ -s "$t/crt.profile" ] || { echo "no profile after resume"; fail=1; }
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
exit $fail
