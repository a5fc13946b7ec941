#!/usr/bin/env bash
# The main job: a per-user CSF calibration session. With no display and no hardware it runs
# headless with the simulated observer and photometer, writing a threshold table, a report plot
# and the session in the results store under ./out/.
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
echo "main: wrote out/display.profile, out/observer.csflut and out/observer.png"
