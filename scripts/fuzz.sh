#!/usr/bin/env bash
# Builds the fuzz targets with clang + libFuzzer (ASan/UBSan) and runs each for N seconds
# (default 20) from its seed corpus. Crash reproducers land in build-fuzz/crashes/.
set -uo pipefail
cd "$(dirname "$0")/.."
secs="${1:-20}"
# CI replays the same mutation sequence each time (-seed=1), so a landing is not decided by a
# lucky draw; run by hand (or with CSF_FUZZ_SEED=0) for fresh random exploration.
seed_opt=""
# Leaks inside system libraries (fontconfig caches behind cairo text, Mesa) are not ours.
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
if [ -n "${CSF_FUZZ_SEED:-}" ]; then seed_opt="-seed=$CSF_FUZZ_SEED"
elif [ "${CI:-}" = true ]; then seed_opt="-seed=1"; fi
if [ ! -f build-fuzz/build.ninja ]; then
  CC=clang CXX=clang++ meson setup build-fuzz -Dfuzz=true -Db_sanitize=address,undefined \
    -Db_lundef=false --buildtype=debugoptimized >/dev/null || exit 1
fi
ninja -C build-fuzz >/dev/null || { ninja -C build-fuzz | tail -30; exit 1; }
mkdir -p build-fuzz/crashes
rc=0
for src in tests/fuzz/fuzz_*.c; do
  t=$(basename "$src" .c)
  bin="build-fuzz/tests/fuzz/$t"
  [ -x "$bin" ] || continue
  work=$(mktemp -d)
  cp -r "tests/fuzz/corpus/$t/." "$work/" 2>/dev/null || true
  if "$bin" -max_total_time="$secs" -max_len=65536 $seed_opt -artifact_prefix=build-fuzz/crashes/"$t"- \
       "$work" >"build-fuzz/$t.log" 2>&1; then
    echo "fuzz: $t ok ($(grep -o 'Done [0-9]* runs' "build-fuzz/$t.log" | tail -1))"
  else
    echo "fuzz: $t FAILED (see build-fuzz/$t.log)"; tail -40 "build-fuzz/$t.log"; rc=1
  fi
  rm -rf "$work"
done
exit $rc
