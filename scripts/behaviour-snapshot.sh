#!/usr/bin/env bash
# Runs a fixed set of csfcal commands with one binary and keeps everything they leave: stdout,
# stderr and exit status of each, the tables, profiles, exports, reports' PNG/SVG, the store's
# rows (sqlite3 .dump) and a quick benchmark's figures. Two snapshots compared with
# `diff -r A B` show whether a change that should not change behaviour (a move, a split) did.
# Times of day and elapsed times are blanked, since they differ between any two runs.
#   scripts/behaviour-snapshot.sh CSFCAL OUTDIR [BENCH_LUT]
set -uo pipefail
CSFCAL=$(realpath "$1")
OUT=$(realpath -m "$2")
BENCH=${3:-}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
rm -rf "$OUT"
mkdir -p "$OUT/work"
cd "$OUT/work"
export EGL_PLATFORM=surfaceless
n=0
blank() { # times of day and elapsed seconds differ between any two runs
  sed -E -e 's/[0-9]{4}-[0-9]{2}-[0-9]{2}[T ][0-9]{2}:[0-9]{2}:[0-9]{2}(\.[0-9]+)?Z?/TIME/g' \
         -e 's/[0-9]+(\.[0-9]+)? s (drawing|in all)/N s \2/g' \
         -e 's/"(duration_s|elapsed_s|wall_s|stored_s|[a-z_]*time_s|[a-z_]*_utc)": ?[0-9.e+-]+/"\1": N/g' \
         -e 's/[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}/UUID/g' \
         -e "s#$OUT/work#WORK#g"
}
run() { # run NAME ARGS...: one command's stdout, stderr and status
  local name=$1; shift
  n=$((n + 1))
  "$CSFCAL" "$@" >"$OUT/$name.out" 2>"$OUT/$name.err"
  echo "$?" >"$OUT/$name.status"
  for f in "$OUT/$name.out" "$OUT/$name.err"; do blank <"$f" >"$f.tmp" && mv "$f.tmp" "$f"; done
}
S=store.sqlite
run display_calibrate display calibrate --photometer sim:display=lcd --seed 3 --store $S --out lcd.profile --quiet
run display_verify display verify lcd.profile --photometer sim:display=lcd --seed 4 --store $S
for f in clf ctf cube icc ocio; do run display_export_$f display export lcd.profile --format $f -o lcd.$f; done
run observer_bayes observer calibrate --observer sim --seed 5 --trials 60 --store $S --profile lcd.profile --out bayes.csflut --plot bayes.png --json
run observer_fade observer calibrate --method fade --observer sim:smax=180 --seed 6 --trials 48 --store $S --profile lcd.profile --out fade.csflut --json
run observer_2afc observer calibrate --method 2afc --afc 2 --observer sim --seed 7 --trials 48 --store $S --profile lcd.profile --out 2afc.csflut
run observer_bad_grid observer calibrate --observer sim --freqs 0.5,200 --store $S --profile lcd.profile --out x.csflut
run stimulus_check stimulus check --freq 4 --ecc 10 --contrast 0.005 --profile lcd.profile --json
run stimulus_geometry stimulus geometry
for f in csv json c glsl; do run lut_export_$f lut export bayes.csflut --format $f -o bayes.$f; done
run lut_info lut info bayes.csflut --json
run lut_lookup lut lookup bayes.csflut --freq 8 --ecc 10 --contrast 0.02 --json
run lut_import lut import bayes.csv -o reimported.csflut
run lut_bad lut info lcd.profile
for s in contrast_2afc same_different yes_no adaptive_2ifc; do
  run study_$s study run "$ROOT/examples/studies/$s.conf" --participant P01 --observer sim --seed 8 --store $S
  run study_report_$s study report "$ROOT/examples/studies/$s.conf" --store $S -o $s.png --csv $s.csv
done
run sessions_list sessions list --store $S --json
for id in 1 2 3 4 5; do
  run sessions_show_$id sessions show $id --store $S --json
  for t in trials readings thresholds frames; do
    run sessions_export_${id}_$t sessions export $id --format csv --table $t --store $S
  done
  run report_$id report $id --store $S -o report_$id.svg
done
run sessions_missing sessions show 999 --store $S
# the observer session's newer paths, in a store of their own (the ids above stay as they were)
S2=store2.sqlite
run observer_velocity observer calibrate --observer sim --seed 9 --velocities 0,4 --freqs 1,4 --eccs 0,10 --store $S2 --profile lcd.profile --out vel.csflut --json
run observer_velocity_fade observer calibrate --method fade --observer sim --seed 9 --velocities 0,4 --freqs 1,4 --eccs 0,10 --trials 32 --store $S2 --profile lcd.profile --out velf.csflut
run observer_precision observer calibrate --observer sim --seed 10 --precision 0.2 --freqs 1,4 --eccs 0,10 --store $S2 --profile lcd.profile --out prec.csflut --json
run observer_view_frame observer calibrate --observer sim:view=frame --seed 11 --trials 24 --freqs 2,8 --eccs 0,5 --store $S2 --profile lcd.profile --out view.csflut
run observer_demo observer calibrate --demo --observer sim --seed 12 --profile lcd.profile
run observer_no_profile observer calibrate --observer sim --seed 13 --trials 12 --freqs 2 --eccs 0 --store $S2 --out noprof.csflut
run observer_bad_precision observer calibrate --observer sim --precision -1 --store $S2 --out x.csflut
run observer_human_headless observer calibrate --observer human --headless --store $S2 --out x.csflut
run observer_resume_done observer calibrate --resume 1 --store $S2 --out x.csflut
run sessions_list2 sessions list --store $S2 --json
for id in 1 2 3 4; do run sessions_export2_$id sessions export $id --format csv --table trials --store $S2; done
run help --help
for t in fade 2afc reimported; do [ -f $t.csflut ] && run lut_info_$t lut info $t.csflut --json; done
# What the commands left behind, as text with the times blanked. Tables are compared through
# `lut info --json` and their exports above; pictures and ICC profiles carry the time they were
# made (drawn or in a header), so only their presence is kept.
for f in *; do
  case $f in
    *.sqlite*) ;;
    *.png|*.icc|*.csflut|*.svg) echo present >"$OUT/file_$f" ;;
    *) blank <"$f" >"$OUT/file_$f" ;;
  esac
done
# Artifacts (tables, plots, profiles) carry the time they were made: their bytes are compared
# through the files above; stored_s columns are Unix times.
sqlite3 $S .dump | sed -E -e "s/^(INSERT INTO artifacts VALUES\([0-9]+,[0-9]+,'[a-z]+','[^']*'),[0-9]+,X'[0-9a-f]+'/\1,SIZE,X'BLOB'/" \
  -e 's/,1[0-9]{9}\.[0-9]+/,UNIXTIME/g' | blank >"$OUT/store.sql"
for t in trials readings frames; do
  sqlite3 -header -csv $S "SELECT * FROM $t" 2>/dev/null | sed -E "s/,1[0-9]{9}\.[0-9]+/,UNIXTIME/g" | blank >"$OUT/store_$t.csv"
done
sqlite3 $S2 .dump | sed -E -e "s/^(INSERT INTO artifacts VALUES\([0-9]+,[0-9]+,'[a-z]+','[^']*'),[0-9]+,X'[0-9a-f]+'/\1,SIZE,X'BLOB'/" \
  -e 's/,1[0-9]{9}\.[0-9]+/,UNIXTIME/g' | blank >"$OUT/store2.sql"
[ -n "$BENCH" ] && "$BENCH" >"$OUT/bench.out" 2>&1
rm -rf "$OUT/work"
echo "snapshot: $n commands in $OUT"
