#!/bin/sh
# `csfcal devices` lists the simulated devices and the offscreen renderer as valid JSON, and under
# Xvfb also the X screen as a monitor with its resolution.
set -u
exe="$1"
fail=0
out=$("$exe" devices --json --headless) || { echo "devices --json failed"; exit 1; }
echo "$out" | python3 -c '
import json, sys
d = json.load(sys.stdin)
kinds = {x["kind"] for x in d}
assert {"photometer", "observer", "renderer"} <= kinds, kinds
assert any(x["spec"] == "sim" and x["kind"] == "photometer" for x in d)
' || { echo "devices JSON lacks expected entries: $out"; fail=1; }
if command -v xvfb-run >/dev/null 2>&1; then
  out=$(env -u WAYLAND_DISPLAY xvfb-run -a -s "-noreset -screen 0 1280x1024x24" "$exe" devices 2>&1)
  echo "$out" | grep -q "1280x1024 px" || { echo "no monitor under Xvfb: $out"; fail=1; }
fi
if "$exe" devices --bogus 2>/dev/null; then echo "unknown option accepted"; fail=1; fi
exit $fail
