#!/usr/bin/env bash
# The main job: a per-user CSF calibration session. With no display and no hardware it runs
# headless with the simulated observer and photometer, writing a threshold table, a report plot
# and the sessions in its own results store, out/csfcal.sqlite (what to type next is printed).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out

./build/cli/csfcal display calibrate --photometer sim:display=lcd --seed 1 \
  --store out/csfcal.sqlite --out out/display.profile
./build/cli/csfcal observer calibrate --observer sim --seed 1 --trials 120 \
  --store out/csfcal.sqlite --profile out/display.profile \
  --out out/observer.csflut --plot out/observer.png "$@"
./build/cli/csfcal lut info out/observer.csflut
# Its own store, out/csfcal.sqlite, not the default one: the sessions are listed only with --store.
cat <<'EOF'
main: wrote out/display.profile, out/observer.csflut and out/observer.png; the two sessions are
in the store out/csfcal.sqlite (not the default store). Next:
  build/cli/csfcal sessions --store out/csfcal.sqlite                           # the sessions
  build/cli/csfcal report 2 --store out/csfcal.sqlite -o observer-report.pdf    # session 2's report
  build/cli/csfcal lut lookup out/observer.csflut --freq 4 --ecc 10 --contrast 0.01
EOF
