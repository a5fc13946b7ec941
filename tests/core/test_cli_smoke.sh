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
exit $fail
