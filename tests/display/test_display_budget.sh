#!/bin/sh
# A budget too small for the target is said to be so: a line on stderr, "target_met": false in
# --json, target_met = 0 in the profile, and verify repeats it; a budget that suffices says met.
set -u
exe="$1"
fail=0
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
export XDG_CONFIG_HOME="$t/cfg" XDG_DATA_HOME="$t/data"
ph='sim:display=lcd,noise=0.005'
"$exe" display calibrate --photometer "$ph" --seed 3 --store "$t/s.sqlite" --out "$t/short.profile" --budget 8 \
  --no-render --json > "$t/j" 2> "$t/e" || { echo "calibrate failed: $(cat "$t/e")"; fail=1; }
grep -q 'target not met' "$t/e" || { echo "no stderr line for an unmet target: $(cat "$t/e")"; fail=1; }
python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["target_met"] is False and d["budget"] == 8, d' \
  < "$t/j" || { echo "json: $(cat "$t/j")"; fail=1; }
grep -q '^target_met = 0$' "$t/short.profile" || { echo "profile does not record the unmet target"; fail=1; }
"$exe" display verify "$t/short.profile" --photometer "$ph" --seed 4 --no-render --json > "$t/v" 2> "$t/ve"
grep -q 'budget ended before the target' "$t/ve" || { echo "verify does not repeat it: $(cat "$t/ve")"; fail=1; }
python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["profile_target_met"] is False and d["profile_stated_rel"] > 0.0025, d' \
  < "$t/v" || { echo "verify json: $(cat "$t/v")"; fail=1; }
# a quiet instrument meets the default target within the default budget, and says so
"$exe" display calibrate --photometer 'sim:display=lcd,noise=0.0002' --seed 3 --store "$t/s.sqlite" \
  --out "$t/ok.profile" --no-render --json > "$t/j" 2> "$t/e" || { echo "calibrate failed: $(cat "$t/e")"; fail=1; }
grep -q 'target not met' "$t/e" && { echo "unmet reported for a met target: $(cat "$t/e")"; fail=1; }
python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["target_met"] is True and max(d["met_error_rel"].values()) <= 0.0025 and all(d["met_error_rel"][k] >= v for k, v in d["error_indicator_rel"].items()), d' \
  < "$t/j" || { echo "json: $(cat "$t/j")"; fail=1; }
grep -q '^target_met = 1$' "$t/ok.profile" || { echo "profile does not record the met target"; fail=1; }
exit $fail
