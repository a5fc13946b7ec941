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
grep -q "$tmp:2: viewing_distance_mm = -3 is out of range (allowed 100 to 20000 mm)" "$tmp.err" \
  || { echo "bad config message: $(cat "$tmp.err")"; fail=1; }
# Command-line overrides are range-checked too.
"$exe" devices --headless --distance-mm 5 >/dev/null 2>"$tmp.err" && { echo "--distance-mm 5 accepted"; fail=1; }
grep -q "allowed 100 to 20000" "$tmp.err" || { echo "override message: $(cat "$tmp.err")"; fail=1; }
rm -f "$tmp" "$tmp.err"
exit $fail
