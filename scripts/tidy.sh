#!/usr/bin/env bash
# clang-tidy (.clang-tidy's checks, warnings as errors) over csfcal's own sources, using the
# compile commands of a configured build folder (default build-test). Exits non-zero on any
# finding.
set -uo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-test}
root=$(pwd)
# Colour codes stripped, so that the findings can be counted.
out=$(run-clang-tidy-14 -p "$build" -j "$(nproc)" -quiet \
      "^$root/(core|results|model|devices|stimuli|calib|studies|cli|examples)/.*\.(c|cpp)$" 2>&1 |
      sed -E 's/\x1b\[[0-9;]*m//g')
rc=$?
# A diagnostic may run over several lines; its last one ends with the check's name in brackets.
findings=$(printf '%s\n' "$out" | grep -E '\[(clang-analyzer|bugprone|misc)-[a-zA-Z0-9.,-]+\]$' | sort -u | wc -l)
if [ $rc -ne 0 ] || [ "$findings" -ne 0 ]; then
  printf '%s\n' "$out" | grep -E -A3 '(warning|error): ' | head -200
  echo "tidy: $findings finding(s)"
  exit 1
fi
echo "tidy: clean"
