#!/usr/bin/env bash
# The lines a change touched in C, C++ and header files follow .clang-format. "A change" is
# everything since the commit named in .ci/format-base (older lines keep their layout until
# someone edits them). Prints each offending hunk as clang-format would write it and exits 1;
# `scripts/check-format.sh --fix` rewrites those lines in place instead.
set -euo pipefail
cd "$(dirname "$0")/.."
base=$(cat .ci/format-base)
fix=""
[ "${1:-}" = "--fix" ] && fix="-i"
if ! git cat-file -e "$base^{commit}" 2>/dev/null; then
  echo "check-format: the base commit $base is not in this clone; checking the last commit only"
  base=HEAD~1
fi
out=$(git diff -U0 --no-color -M "$base" -- '*.c' '*.h' '*.cpp' ':!tests/fuzz/corpus' |
      clang-format-diff-14 -p1 -style=file $fix)
if [ -n "$fix" ]; then echo "check-format: changed lines reformatted"; exit 0; fi
if [ -n "$out" ]; then
  echo "$out"
  echo "check-format: the lines above do not follow .clang-format (fix: scripts/check-format.sh --fix)"
  exit 1
fi
echo "check-format: changed lines since ${base:0:12} follow .clang-format"
