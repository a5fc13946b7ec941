#!/bin/sh
# Cross-check of the study report's fits against psignifit 4 under Octave.
# Needs octave-cli (Debian: apt-get install octave; not needed by the build or the tests) and a
# psignifit 4 checkout (MATLAB/Octave version, https://github.com/wichmann-lab/psignifit): it is
# run from where it is, never copied into this repository.
#   usage: bench/anchors/check_psignifit.sh BUILD_DIR [PSIGNIFIT_DIR]   (default $CSF_PSIGNIFIT_DIR)
# Prints one row per data set (20: 2afc 6x40, 5x20, 8x60 and yes/no 6x40, five each) and a summary;
# exits 1 when the two disagree beyond the limits in psignifit_anchor.m, 77 (skip) without
# octave-cli or psignifit (the meson test `anchors_psignifit` runs it that way).
set -eu
build=${1:?usage: check_psignifit.sh BUILD_DIR [PSIGNIFIT_DIR]}
psig=${2:-${CSF_PSIGNIFIT_DIR:-}}
command -v octave-cli >/dev/null || { echo "octave-cli not found (apt-get install octave): skipped" >&2; exit 77; }
[ -n "$psig" ] || { echo "no psignifit: give PSIGNIFIT_DIR or set CSF_PSIGNIFIT_DIR: skipped" >&2; exit 77; }
[ -f "$psig/psignifit.m" ] || { echo "no psignifit.m in $psig" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$build/bench/bench_anchor_data" "$tmp/levels.csv" "$tmp/fits.csv"
cd "$tmp" && octave-cli -q "$here/psignifit_anchor.m" "$psig" "$tmp/levels.csv" "$tmp/fits.csv"
