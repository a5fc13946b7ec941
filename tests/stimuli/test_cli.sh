#!/bin/sh
# csfcal stimulus check/geometry from the command line: a passing self-check in JSON, and
# refusals (Nyquist, off-screen, bad numbers) with a message naming the limit and exit status != 0.
CSFCAL="$1"
fail=0
err() { echo "FAIL: $*"; fail=1; }
export EGL_PLATFORM=surfaceless
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
small="--headless --screen-px 640x360 --photometer sim:display=crt,gamma=2.4"

"$CSFCAL" stimulus --help >"$T/help" 2>&1 || err "--help exit status"
grep -q "stimulus check" "$T/help" || err "--help text"

"$CSFCAL" stimulus check --freq 2 --ecc 5 --contrast 0.01 --frames 20 --levels 4 --json $small \
  >"$T/out.json" 2>"$T/err" || { err "check failed"; cat "$T/err"; }
grep -q '"measured"' "$T/out.json" || err "no measured block"
awk -F'"contrast_rel_error": ' 'NF>1 { split($2, a, ","); v=a[1]; if (v < 0) v=-v; if (v > 0.03) exit 1 }' \
  "$T/out.json" || err "contrast error above 3 %: $(cat "$T/out.json")"
awk -F'"effective_bits": ' 'NF>1 { split($2, a, "}"); if (a[1] < 12) exit 1 }' "$T/out.json" \
  || err "effective bits below 12"

"$CSFCAL" stimulus check --freq 20 --ecc 0 --contrast 0.01 $small >"$T/o" 2>"$T/e"
[ $? -ne 0 ] || err "Nyquist request accepted"
grep -q "Nyquist limit of" "$T/e" || err "Nyquist message: $(cat "$T/e")"

"$CSFCAL" stimulus check --freq 2 --ecc 40 --contrast 0.01 $small >"$T/o" 2>"$T/e"
[ $? -ne 0 ] || err "off-screen request accepted"
grep -q "screen reaches" "$T/e" || err "off-screen message: $(cat "$T/e")"

"$CSFCAL" stimulus check --freq 2 --contrast 2 $small >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "bad contrast exit status"
grep -q "contrast" "$T/e" || err "bad contrast message: $(cat "$T/e")"

"$CSFCAL" stimulus check --freq 2 --contrast 0.1 --photometer usb:colorcal >"$T/o" 2>"$T/e"
[ $? -ne 0 ] || err "real photometer accepted as truth"

"$CSFCAL" stimulus geometry --ecc 10 --json >"$T/g" 2>&1 || err "geometry failed"
grep -q '"nyquist_cpd"' "$T/g" || err "geometry json"
"$CSFCAL" stimulus bogus >"$T/o" 2>"$T/e"
[ $? -eq 2 ] || err "unknown subcommand status"
exit $fail
