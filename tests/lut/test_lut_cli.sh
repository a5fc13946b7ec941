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
"$CSFCAL" lut info "$T/none.csflut" >"$T/out" 2>&1; expect "missing file says why" 1 "cannot open .*none.csflut: No such file or directory" "$T/out" $?
"$CSFCAL" lut info "$T" >"$T/out" 2>&1; expect "a folder says why" 1 "Is a directory" "$T/out" $?
# --date must be a real UTC date and time, and the message names the form
for d in yesterday 2026-13-45T99:99:99Z 2026-02-29T00:00:00Z 2026-11-23 2026-11-23T10:00:00 2026-04-31T00:00:00Z; do
    "$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$T/d.csflut" --date "$d" >"$T/out" 2>&1
    expect "--date $d refused" 2 "YYYY-MM-DDTHH:MM:SSZ" "$T/out" $?
done
[ ! -e "$T/d.csflut" ] && ok "no table for a bad date" || bad "no table for a bad date"
"$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$T/d.csflut" --date 2024-02-29T23:59:60Z >"$T/out" 2>&1
[ $? = 0 ] && [ -s "$T/d.csflut" ] && ok "--date leap day, leap second accepted" || { bad "--date leap day accepted"; cat "$T/out"; }
# export -> import keeps every metadata field the CSV export writes
"$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$T/m.csflut" --observer "Ann O." \
    --display-profile "lcd-7 #2" --method fade --date 2025-01-02T03:04:05Z --distance-mm 650 \
    --mean-lum 90 --trials 120 >"$T/out" 2>&1 || bad "import with metadata"
"$CSFCAL" lut export "$T/m.csflut" --format csv -o "$T/m.csv" || bad "export m"
"$CSFCAL" lut import "$T/m.csv" -o "$T/m2.csflut" >"$T/out" 2>&1 || bad "re-import m"
"$CSFCAL" lut export "$T/m2.csflut" --format csv -o "$T/m2.csv" || bad "export m2"
grep -c '^# [a-z0-9_]*: ' "$T/m.csv" | grep -qx 8 && ok "csv export has 8 metadata fields" || bad "csv export has 8 metadata fields"
cmp -s "$T/m.csv" "$T/m2.csv" && ok "metadata round trip (every line equal)" || { bad "metadata round trip"; diff "$T/m.csv" "$T/m2.csv"; }
"$CSFCAL" lut info "$T/m.csflut" --json 2>&1 | sed 's/"file": "[^"]*"//' >"$T/j1"
"$CSFCAL" lut info "$T/m2.csflut" --json 2>&1 | sed 's/"file": "[^"]*"//' >"$T/j2"
cmp -s "$T/j1" "$T/j2" && grep -q '"display_profile_id": "lcd-7 #2"' "$T/j2" && ok "metadata round trip (info --json equal)" || { bad "info json equal"; diff "$T/j1" "$T/j2"; }
"$CSFCAL" lut import "$T/m.csv" -o "$T/m3.csflut" --observer Bob --trials 7 >"$T/out" 2>&1 || bad "re-import with overrides"
"$CSFCAL" lut info "$T/m3.csflut" --json >"$T/out" 2>&1
grep -q '"observer": "Bob"' "$T/out" && grep -q '"trials": 7' "$T/out" && grep -q '"method": "fade"' "$T/out" && ok "options override the CSV metadata" || { bad "options override"; cat "$T/out"; }
printf '# trials: many\nfreq_cpd,ecc_deg,threshold\n1,0,0.01\n' >"$T/badmeta.csv"
"$CSFCAL" lut import "$T/badmeta.csv" -o "$T/c.csflut" >"$T/out" 2>&1; expect "bad metadata comment names line 1" 1 "line 1.*trials" "$T/out" $?
# An output that does not fit (RLIMIT_FSIZE, SIGXFSZ ignored: fails like a full
# disk) leaves no partial file and no temporary, keeps what was there, and says why
echo old >"$T/keep.c"
(trap '' XFSZ; ulimit -f 2; exec "$CSFCAL" lut export "$T/a.csflut" --format c -o "$T/keep.c") >"$T/out" 2>&1
expect "export past the file size limit fails with the OS error" 1 "File too large" "$T/out" $?
[ "$(cat "$T/keep.c")" = old ] && ok "export: destination kept" || bad "export: destination kept"
(trap '' XFSZ; ulimit -f 1; exec "$CSFCAL" lut import "$T/m.csv" -o "$T/full.csflut") >"$T/out" 2>&1
expect "import past the file size limit fails with the OS error" 1 "File too large" "$T/out" $?
[ ! -e "$T/full.csflut" ] && ok "import: no partial table" || bad "import: no partial table"
ls "$T" | grep -q 'tmp' && { bad "temporaries left behind"; ls "$T"; } || ok "no temporaries left behind"
"$CSFCAL" lut export "$T/a.csflut" --format c -o "$T/nodir/x.c" >"$T/out" 2>&1; expect "export into a missing folder refused up front" 2 "nodir" "$T/out" $?
"$CSFCAL" lut import "$T/m.csv" -o "$T/nodir/x.csflut" >"$T/out" 2>&1; expect "import into a missing folder refused up front" 2 "nodir" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq -1 --ecc 0 >"$T/out" 2>&1; expect "negative freq" 2 "allowed" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 4 >"$T/out" 2>&1; expect "missing --ecc" 2 "required" "$T/out" $?
"$CSFCAL" lut export "$T/a.csflut" --format xml >"$T/out" 2>&1; expect "bad format" 2 "csv, json, c, glsl" "$T/out" $?
"$CSFCAL" lut export "$T/a.csflut" --format c --prefix 1x >"$T/out" 2>&1; expect "bad prefix" 2 "C identifier" "$T/out" $?
# every generated name starts with the prefix: GLSL refuses gl_..., GLSL and C++ reserve __ (also
# made by a trailing _ before _threshold); refused up front, in every format, naming the rule
for fmt in glsl c; do
    "$CSFCAL" lut export "$T/a.csflut" --format $fmt --prefix gl_x -o "$T/p.$fmt" >"$T/out" 2>&1
    expect "--prefix gl_x refused ($fmt)" 2 "'gl_x' starts with \"gl_\": GLSL reserves names starting with gl_" "$T/out" $?
    "$CSFCAL" lut export "$T/a.csflut" --format $fmt --prefix a__b -o "$T/p.$fmt" >"$T/out" 2>&1
    expect "--prefix a__b refused ($fmt)" 2 "'a__b' contains \"__\": GLSL and C++ reserve names containing two consecutive underscores" "$T/out" $?
    "$CSFCAL" lut export "$T/a.csflut" --format $fmt --prefix lut_ -o "$T/p.$fmt" >"$T/out" 2>&1
    expect "--prefix lut_ refused ($fmt)" 2 "'lut_' ends with '_', so lut__threshold would contain \"__\"" "$T/out" $?
    [ ! -e "$T/p.$fmt" ] && ok "no $fmt export for a refused prefix" || bad "no $fmt export for a refused prefix"
done
"$CSFCAL" lut export "$T/a.csflut" --format glsl --prefix GL_lut_2 -o "$T/p.glsl" >"$T/out" 2>&1 \
    && grep -q "float GL_lut_2_threshold" "$T/p.glsl" && ok "--prefix GL_lut_2 accepted" || { bad "--prefix GL_lut_2 accepted"; cat "$T/out"; }
# A 3-D table (freq x ecc x velocity), as the observer calibration writes it: metadata pairs in
# "# meta.KEY: value" comments, a velocity_dps column including 0
python3 - "$T/v.csv" <<'PY'
import math, sys
with open(sys.argv[1], "w") as f:
    f.write("# meta.velocity_meaning: retinal (fixation on the mark: screen velocity)\n")
    f.write("# meta.cells_not_shown: f=16 cpd v=8 deg/s (tf 128 Hz >= 60 Hz)\n")
    f.write("freq_cpd,ecc_deg,velocity_dps,threshold,stderr_log10\n")
    for v in (0, 2, 8):
        for e in (0, 10):
            for fr in (1, 4, 16):
                t = 0.004 * (fr / 4) ** 2 * (1 + e / 10) * (1 + v / 4) if fr > 1 else 0.01
                se = 1.0 if (fr == 16 and v == 8) else 0.05
                f.write("%g,%g,%g,%.17g,%g\n" % (fr, e, v, t, se))
PY
"$CSFCAL" lut import "$T/v.csv" -o "$T/v.csflut" >"$T/out" 2>&1 && ok "import 3-D" || { bad "import 3-D"; cat "$T/out"; }
"$CSFCAL" lut info "$T/v.csflut" >"$T/out" 2>&1; expect "info: velocity axis and warp" 0 "axis velocity     3 points, warp log(|v| + 0.5), 0 to 8 deg/s" "$T/out" $?
grep -q "meta velocity_meaning retinal (fixation on the mark: screen velocity)" "$T/out" && grep -q "format version:    1.1" "$T/out" \
    && ok "info: metadata pairs, format 1.1" || { bad "info: metadata pairs"; cat "$T/out"; }
"$CSFCAL" lut info "$T/v.csflut" --json >"$T/out" 2>&1
python3 - "$T/out" <<'PY' && ok "info json: velocity axis, warp, meta" || bad "info json: velocity axis, warp, meta"
import json, sys
d = json.load(open(sys.argv[1]))
v = d["axes"][2]
assert v["name"] == "velocity" and v["points"] == [0, 2, 8] and v["warp_v0_dps"] == 0.5, v
assert d["meta"]["cells_not_shown"].startswith("f=16 cpd"), d["meta"]
PY
# lookup at a node, at 0 and between nodes (the warp: at sqrt(2.5 * 8.5) - 0.5 deg/s the threshold
# is the geometric mean of the 2 and 8 deg/s nodes)
"$CSFCAL" lut lookup "$T/v.csflut" --freq 4 --ecc 0 --velocity 2 --raw --json >"$T/out" 2>&1
python3 -c "import json; d=json.load(open('$T/out')); assert abs(d['threshold'] / 0.006 - 1) < 1e-14, d" \
    && ok "lookup --velocity at a node" || { bad "lookup --velocity at a node"; cat "$T/out"; }
"$CSFCAL" lut lookup "$T/v.csflut" --freq 4 --ecc 0 --velocity 0 --raw --json >"$T/out" 2>&1
expect "lookup --velocity 0" 0 '"velocity_dps": 0,' "$T/out" $?
vm=$(python3 -c "import math; print(repr(math.sqrt(2.5 * 8.5) - 0.5))")
"$CSFCAL" lut lookup "$T/v.csflut" --freq 4 --ecc 0 --velocity "$vm" --raw --json --contrast 0.01 >"$T/out" 2>&1
python3 - "$T/out" <<'PY' && ok "lookup between velocity nodes (warp), max frequency" || { bad "lookup between velocity nodes"; cat "$T/out"; }
import json, math, sys
d = json.load(open(sys.argv[1]))
want = math.sqrt(0.004 * 1.5 * 0.004 * 3.0)
assert abs(d["threshold"] / want - 1) < 1e-12, d
assert 4 < d["max_frequency_cpd"] < 16, d
PY
"$CSFCAL" lut lookup "$T/v.csflut" --freq 4 --ecc 0 --velocity -1 >"$T/out" 2>&1; expect "negative --velocity" 2 "allowed" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 4 --ecc 0 --velocity 2 >"$T/out" 2>&1; expect "--velocity on a 2-D table" 2 "has no velocity axis" "$T/out" $?
# export -> import keeps the velocity axis and the pairs, line for line
"$CSFCAL" lut export "$T/v.csflut" --format csv -o "$T/v2.csv" || bad "export 3-D csv"
"$CSFCAL" lut import "$T/v2.csv" -o "$T/v2.csflut" >"$T/out" 2>&1 || bad "re-import 3-D"
"$CSFCAL" lut export "$T/v2.csflut" --format csv -o "$T/v3.csv" || bad "export 3-D csv again"
cmp -s "$T/v2.csv" "$T/v3.csv" && grep -q "^# meta.cells_not_shown: f=16" "$T/v3.csv" && ok "3-D csv round trip with metadata pairs" || { bad "3-D csv round trip"; diff "$T/v2.csv" "$T/v3.csv"; }
for fmt in c glsl; do
    "$CSFCAL" lut export "$T/v.csflut" --format $fmt -o "$T/v.$fmt" 2>"$T/err" && grep -q "csflut_gen_threshold3" "$T/v.$fmt" && ok "3-D export $fmt has threshold3" || bad "3-D export $fmt"
done
# refusals of 3-D grids name the line and the rule
printf 'freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,0,0.01\n1,0,-2,0.01\n' >"$T/vbad.csv"
"$CSFCAL" lut import "$T/vbad.csv" -o "$T/c.csflut" >"$T/out" 2>&1; expect "negative velocity names line 3 and the limit" 1 "line 3: velocity_dps -2 must be finite and >= 0 deg/s" "$T/out" $?
printf 'freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,0,0.01\n1,0,nan,0.01\n' >"$T/vbad.csv"
"$CSFCAL" lut import "$T/vbad.csv" -o "$T/c.csflut" >"$T/out" 2>&1; expect "NaN velocity names line 3" 1 "line 3: velocity_dps nan must be finite" "$T/out" $?
printf 'freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,0,0.01\n2,0,0,0.01\n1,0,4,0.01\n' >"$T/vbad.csv"
"$CSFCAL" lut import "$T/vbad.csv" -o "$T/c.csflut" >"$T/out" 2>&1; expect "hole in a 3-D grid named" 1 "no row for freq_cpd=2 ecc_deg=0 velocity_dps=4" "$T/out" $?
printf 'freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,0,0.01\n1,0,4,0.01\n1,0,4,0.02\n' >"$T/vbad.csv"
"$CSFCAL" lut import "$T/vbad.csv" -o "$T/c.csflut" >"$T/out" 2>&1; expect "duplicate in a 3-D grid names both lines" 1 "line 4: duplicate grid point (same axis values as line 3)" "$T/out" $?
printf '# meta.a b: x\nfreq_cpd,ecc_deg,threshold\n1,0,0.01\n' >"$T/vbad.csv"
"$CSFCAL" lut import "$T/vbad.csv" -o "$T/c.csflut" >"$T/out" 2>&1; expect "bad metadata key names line 1" 1 "line 1: metadata key" "$T/out" $?
[ ! -e "$T/c.csflut" ] && ok "no table from a refused 3-D grid" || bad "no table from a refused 3-D grid"
"$CSFCAL" lut frobnicate >"$T/out" 2>&1; expect "unknown subcommand" 2 "unknown subcommand" "$T/out" $?
"$CSFCAL" lut info "$T/a.csflut" --bogus >"$T/out" 2>&1; expect "unknown option" 2 "unknown option" "$T/out" $?
"$CSFCAL" lut lookup "$T/a.csflut" --freq 4 --ecc 0 --shift 11 >"$T/out" 2>&1; expect "shift range" 2 "allowed 0 to 10" "$T/out" $?
exit $fail
