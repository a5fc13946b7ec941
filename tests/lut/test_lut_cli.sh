#!/bin/sh
# csfcal lut from the shell: import the bundled example CSV, info/lookup (text and JSON), export
# every format, re-import the exported CSV and check the values survive; bad input is refused
# with a message naming the problem and a non-zero exit status.
set -u
CSFCAL=$1
EXAMPLES=$2
T=$(mktemp -d /tmp/csflut-cli-XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
ok() { echo "ok: $1"; }
bad() { echo "FAIL: $1"; fail=1; }
expect() { # expect DESCRIPTION STATUS GREP-PATTERN FILE
    if [ "$2" = "$5" ] && grep -q -- "$3" "$4"; then ok "$1"; else bad "$1 (status $5, want $2)"; cat "$4"; fi
}

"$CSFCAL" lut --help >"$T/out" 2>&1; expect "lut --help" 0 "lut lookup FILE" "$T/out" $?
"$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$T/a.csflut" --observer "Ann O." \
    --distance-mm 650 --mean-lum 90 --trials 120 --method fade >"$T/out" 2>&1 \
    && [ -s "$T/a.csflut" ] && ok "import example" || { bad "import example"; cat "$T/out"; }
"$CSFCAL" lut info "$T/a.csflut" >"$T/out" 2>&1; expect "info text" 0 "8 points, log scale, 0.5 to 32 cpd" "$T/out" $?
grep -q "Ann O." "$T/out" && grep -q "650 mm" "$T/out" || bad "info shows metadata"
"$CSFCAL" lut info "$T/a.csflut" --json >"$T/out" 2>&1; expect "info json" 0 '"trials": 120' "$T/out" $?
python3 -c "import json,sys; d=json.load(open('$T/out')); assert d['nodes']==48 and d['axes'][1]['points']==[0,5,10,20,30,40]" \
    && ok "info json parses" || bad "info json parses"
# the bundled binary example is the same table as its CSV source
"$CSFCAL" lut export "$EXAMPLES/example_default_observer.csflut" --format csv -o "$T/bundled.csv" 2>"$T/err" || bad "export bundled"
"$CSFCAL" lut export "$T/a.csflut" --format csv -o "$T/a.csv" 2>"$T/err" || bad "export csv"
[ "$(grep -v '^#' "$T/bundled.csv" | md5sum)" = "$(grep -v '^#' "$T/a.csv" | md5sum)" ] && ok "bundled example matches CSV" || bad "bundled example matches CSV"
# round trip: exported CSV re-imports to identical values (compare the exports)
"$CSFCAL" lut import "$T/a.csv" -o "$T/b.csflut" >"$T/out" 2>&1 || bad "re-import"
"$CSFCAL" lut export "$T/b.csflut" --format csv -o "$T/b.csv" || bad "export b"
[ "$(grep -v '^#' "$T/a.csv" | md5sum)" = "$(grep -v '^#' "$T/b.csv" | md5sum)" ] && ok "csv round trip" || bad "csv round trip"
# lookup: conservative and raw, JSON parse, contrast and inverse
"$CSFCAL" lut lookup "$T/a.csflut" --freq 4 --ecc 0 --contrast 0.01 >"$T/out" 2>&1
expect "lookup text" 0 "perceptible" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 4 --ecc 0 --raw --json >"$T/out" 2>&1
expect "lookup raw json" 0 '"threshold": 0.0042179976113569965' "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 0.5 --ecc 0 --json >"$T/out" 2>&1
expect "lookup conservative clamps below peak" 0 '"threshold": 0.0042179976113569965' "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 32 --ecc 40 --json >"$T/out" 2>&1
expect "never visible" 0 '"never_visible": true' "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 3 --ecc 2 --contrast 0.01 --json >"$T/out" 2>&1
python3 - "$T/out" <<'PY' && ok "lookup json inverse" || bad "lookup json inverse"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["perceptible"] is True and 3 < d["max_frequency_cpd"] < 32, d
PY
for fmt in csv json c glsl; do
    "$CSFCAL" lut export "$T/a.csflut" --format $fmt -o "$T/x.$fmt" 2>"$T/err" && [ -s "$T/x.$fmt" ] && ok "export $fmt" || bad "export $fmt"
done
python3 -c "import json; d=json.load(open('$T/x.json')); assert len(d['threshold'])==48" && ok "json export parses" || bad "json export parses"
grep -q "csflut_gen_threshold" "$T/x.c" && ok "C export names" || bad "C export names"
# refusals
printf 'freq_cpd,ecc_deg,threshold\n1,0,0.01\n2,0,oops\n' >"$T/bad.csv"
"$CSFCAL" lut import "$T/bad.csv" -o "$T/c.csflut" >"$T/out" 2>&1; expect "bad csv names line 3" 1 "line 3" "$T/out" $?
[ ! -e "$T/c.csflut" ] && ok "no output on bad csv" || bad "no output on bad csv"
head -c 100 "$T/a.csflut" >"$T/trunc.csflut"
"$CSFCAL" lut info "$T/trunc.csflut" >"$T/out" 2>&1; expect "truncated file" 1 "truncated" "$T/out" $?
"$CSFCAL" lut info "$EXAMPLES/example_default_observer.csv" >"$T/out" 2>&1; expect "csv is not a table" 1 "magic" "$T/out" $?
"$CSFCAL" lut info "$T/none.csflut" >"$T/out" 2>&1; expect "missing file" 1 "cannot open" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq -1 --ecc 0 >"$T/out" 2>&1; expect "negative freq" 2 "allowed" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 4 >"$T/out" 2>&1; expect "missing --ecc" 2 "required" "$T/out" $?
"$CSFCAL" lut export "$T/a.csflut" --format xml >"$T/out" 2>&1; expect "bad format" 2 "csv, json, c, glsl" "$T/out" $?
"$CSFCAL" lut export "$T/a.csflut" --format c --prefix 1x >"$T/out" 2>&1; expect "bad prefix" 2 "C identifier" "$T/out" $?
"$CSFCAL" lut frobnicate >"$T/out" 2>&1; expect "unknown subcommand" 2 "unknown subcommand" "$T/out" $?
"$CSFCAL" lut info "$T/a.csflut" --bogus >"$T/out" 2>&1; expect "unknown option" 2 "unknown option" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 4 --ecc 0 --shift 11 >"$T/out" 2>&1; expect "shift range" 2 "allowed 0 to 10" "$T/out" $?
exit $fail
