#!/bin/bash
# calibration -> table -> simplified renders -> same/different study -> report, headless with the
# simulated observer (Luebke & Hallen 2001, sec. 6.2; docs/studies.md).
#   usage: run.sh CSFCAL LOD OUT_DIR [PARTICIPANTS=4]
# Writes OUT_DIR/observer.csflut (the simulated person's calibration, bayes 120 trials),
# OUT_DIR/images/ (full and simplified renders, conditions.csv), OUT_DIR/study.sqlite and
# OUT_DIR/report.json. Exit 0 when every step ran; the verdicts are in the report.
set -eu
CSFCAL=$1 LOD=$2 OUT=$3 N=${4:-4}
HERE=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT/images"
cp "$HERE/luebke_hallen.conf" "$OUT/"
STORE="$OUT/study.sqlite"
rm -f "$STORE" "$OUT/calib.sqlite"
# 1. the person's threshold table (the same simulated person answers the study below)
"$CSFCAL" observer calibrate --headless --observer sim --seed 7 --trials 120 \
    --store "$OUT/calib.sqlite" --out "$OUT/observer.csflut" --quiet
# 2. full and simplified renders, 16 px/deg, two viewpoints; d1 = imperceptible, d8 and k16 perceptible
"$LOD" --table "$OUT/observer.csflut" --out "$OUT/images" --size 256x192 --ppd 16 --object-deg 8 \
    --views 2 --distance-factors 1,8 --threshold-factors 16 >"$OUT/lod.log"
# 3. the study, each participant a different simulated person's answers (seed)
for p in $(seq 1 "$N"); do
    "$CSFCAL" study run "$OUT/luebke_hallen.conf" --participant "P$p" --observer sim --seed "$p" \
        --store "$STORE" --headless --quiet
done
# 4. the report
"$CSFCAL" study report "$OUT/luebke_hallen.conf" --json --store "$STORE" >"$OUT/report.json"
"$CSFCAL" study report "$OUT/luebke_hallen.conf" --store "$STORE" --csv "$OUT/report.csv" -o "$OUT/report.pdf" >"$OUT/report.txt"
