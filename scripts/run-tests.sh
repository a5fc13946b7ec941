#!/usr/bin/env bash
# Installs dependencies, builds with ASan/UBSan and warnings as errors, runs every test (unit,
# integration, fuzz-corpus replay, and a short libFuzzer run of each fuzz target), checks the
# format of changed lines and runs clang-tidy, and prints the closing line "N passed, N failed".
set -uo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh || { echo "setup failed"; echo "0 passed, 1 failed"; exit 1; }

# Sanitizer options and the EGL platform come from the default test setup in meson.build.

if [ ! -f build-test/build.ninja ]; then
  meson setup build-test -Dwerror=true -Db_sanitize=address,undefined -Db_lundef=false \
    --buildtype=debugoptimized >/dev/null || { echo "0 passed, 1 failed"; exit 1; }
fi
if ! ninja -C build-test; then
  echo "0 passed, 1 failed"; exit 1
fi
meson test -C build-test --num-processes 2 --print-errorlogs "$@"
status=$?

# Count from meson's machine-readable log.
read -r passed failed < <(python3 - build-test/meson-logs/testlog.json <<'PY'
import json, sys
p = f = 0
for line in open(sys.argv[1]):
    r = json.loads(line)
    if r.get("result") in ("OK", "EXPECTEDFAIL"): p += 1
    elif r.get("result") != "SKIP": f += 1
print(p, f)
PY
)

# Changed lines follow .clang-format; clang-tidy's checks are clean (one count each).
lint_passed=0; lint_failed=0
if bash scripts/check-format.sh; then lint_passed=$((lint_passed + 1)); else lint_failed=$((lint_failed + 1)); fi
if [ "${CSF_SKIP_TIDY:-0}" != 1 ]; then
  if bash scripts/tidy.sh build-test; then lint_passed=$((lint_passed + 1)); else lint_failed=$((lint_failed + 1)); fi
fi
passed=$((passed + lint_passed)); failed=$((failed + lint_failed))

# Short coverage-guided fuzzing of every target (clang + libFuzzer).
fuzz_passed=0; fuzz_failed=0
if [ "${CSF_SKIP_FUZZ:-0}" != 1 ]; then
  if bash scripts/fuzz.sh "${CSF_FUZZ_SECONDS:-20}"; then fuzz_passed=1; else fuzz_failed=1; fi
fi
passed=$((passed + fuzz_passed)); failed=$((failed + fuzz_failed))
echo "$passed passed, $failed failed"
[ "$status" -eq 0 ] && [ "$failed" -eq 0 ]
