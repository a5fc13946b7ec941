#!/bin/sh
# The executable answers --version and --help for every subcommand, and refuses unknown ones.
set -u
exe="$1"
fail=0
"$exe" --version | grep -q '^csfcal ' || { echo "no --version"; fail=1; }
"$exe" --help | grep -q 'observer' || { echo "no --help"; fail=1; }
for c in observer display stimulus lut study sessions report devices; do
  "$exe" $c --help >/dev/null 2>&1 || { echo "$c --help failed"; fail=1; }
done
if "$exe" nosuchcommand 2>/dev/null; then echo "unknown command accepted"; fail=1; fi
"$exe" nosuchcommand 2>&1 | grep -q "unknown command" || { echo "no message for unknown command"; fail=1; }
# A bad station configuration is refused with file, line and the allowed range, exit status 2.
tmp=$(mktemp)
printf 'screen_width_mm = 600\nviewing_distance_mm = -3\n' > "$tmp"
"$exe" devices --headless --config "$tmp" >/dev/null 2>"$tmp.err"
rc=$?
[ "$rc" -eq 2 ] || { echo "bad config: exit $rc, expected 2"; fail=1; }
grep -q "$tmp:2: viewing_distance_mm = -3 is out of range (allowed 100 to 10000 mm)" "$tmp.err" \
  || { echo "bad config message: $(cat "$tmp.err")"; fail=1; }
# Command-line overrides are range-checked too.
"$exe" devices --headless --distance-mm 5 >/dev/null 2>"$tmp.err" && { echo "--distance-mm 5 accepted"; fail=1; }
grep -q "allowed 100 to 10000" "$tmp.err" || { echo "override message: $(cat "$tmp.err")"; fail=1; }
# A folder as --config is refused (it was read as an empty file: every value a silent default).
d=$(mktemp -d)
"$exe" devices --headless --config "$d" >/dev/null 2>"$tmp.err"
rc=$?
[ "$rc" -eq 2 ] || { echo "--config DIR: exit $rc, expected 2"; fail=1; }
grep -q "configuration file $d is a folder, not a file" "$tmp.err" || { echo "--config DIR message: $(cat "$tmp.err")"; fail=1; }
# --store "" is refused (it used the default store), and nothing is created.
XDG_DATA_HOME="$d" "$exe" observer calibrate --headless --store "" --out "$d/x.csflut" --trials 1 --freqs 1 --eccs 0 \
  >/dev/null 2>"$tmp.err"
rc=$?
[ "$rc" -eq 2 ] || { echo "--store '': exit $rc, expected 2"; fail=1; }
grep -q -- "--store: empty path (give a file, or leave --store out for the default $d/csfcal/csfcal.sqlite)" "$tmp.err" \
  || { echo "--store '' message: $(cat "$tmp.err")"; fail=1; }
[ ! -e "$d/csfcal" ] && [ ! -e "$d/x.csflut" ] || { echo "--store '': something was written"; fail=1; }
# A bad option is named (the message said "bad option"), and no "----" doubled dashes.
"$exe" observer calibrate --headless --freqz 2 --out "$d/x.csflut" >/dev/null 2>"$tmp.err"
rc=$?
[ "$rc" -eq 2 ] || { echo "--freqz: exit $rc, expected 2"; fail=1; }
grep -q "observer calibrate: unknown option '--freqz' (try csfcal observer calibrate --help)" "$tmp.err" \
  || { echo "--freqz message: $(cat "$tmp.err")"; fail=1; }
"$exe" stimulus check --headless --freq abc --ecc 0 --contrast 0.5 >/dev/null 2>"$tmp.err"
grep -q -- "--freq: 'abc' is not a number" "$tmp.err" && ! grep -q -- '---' "$tmp.err" \
  || { echo "--freq abc message: $(cat "$tmp.err")"; fail=1; }
# An empty list item is refused, naming it (it was dropped silently).
"$exe" observer calibrate --headless --freqs 2,,4 --out "$d/x.csflut" >/dev/null 2>"$tmp.err"
rc=$?
[ "$rc" -eq 2 ] || { echo "--freqs 2,,4: exit $rc, expected 2"; fail=1; }
grep -q -- "--freqs: item 2 of '2,,4' is empty" "$tmp.err" || { echo "--freqs 2,,4 message: $(cat "$tmp.err")"; fail=1; }
rm -rf "$d"
rm -f "$tmp" "$tmp.err"
exit $fail
