#!/usr/bin/env bash
# Builds the fuzz targets with clang + libFuzzer (ASan/UBSan) and runs each for N seconds
# (default 20). Seeds: the checked-in corpus (tests/fuzz/corpus/TARGET/) plus fresh real files
# that tests/fuzz/gen-seeds.sh makes with the csfcal just built (a store, profiles, tables,
# exports, a configuration), since a checked-in binary seed goes stale when its format changes.
# Any sanitizer finding, UBSan's included, fails the run; crash reproducers land in
# build-fuzz/crashes/. Per target it prints executions and coverage (libFuzzer's cov = edges,
# ft = features) after loading the seeds and at the end; build-fuzz/fuzz-stats.tsv has the same.
#   CSF_FUZZ_SEED=N        libFuzzer -seed (CI: 1; 0 or unset by hand: random)
#   CSF_FUZZ_FRESH_SEEDS=0 skip the generated seeds (checked-in corpus only)
#   CSF_FUZZ_CORPUS=DIR    another checked-in corpus root (default tests/fuzz/corpus)
#   CSF_FUZZ_TARGETS="a b" only these targets
set -uo pipefail
cd "$(dirname "$0")/.."
secs="${1:-20}"
# CI replays the same mutation sequence each time (-seed=1), so a landing is not decided by a
# lucky draw; run by hand (or with CSF_FUZZ_SEED=0) for fresh random exploration.
seed_opt=""
if [ -n "${CSF_FUZZ_SEED:-}" ]; then seed_opt="-seed=$CSF_FUZZ_SEED"
elif [ "${CI:-}" = true ]; then seed_opt="-seed=1"; fi
corpus="${CSF_FUZZ_CORPUS:-tests/fuzz/corpus}"
# Leaks inside system libraries (fontconfig caches behind cairo text, Mesa) are not ours.
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# UBSan only prints and goes on by default, and libFuzzer would count the run as clean: make
# every UBSan report fatal (the build also says -fno-sanitize-recover=all), with a stack.
export UBSAN_OPTIONS="halt_on_error=1:abort_on_error=1:print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"

if [ ! -f build-fuzz/build.ninja ]; then
  CC=clang CXX=clang++ meson setup build-fuzz -Dfuzz=true -Db_sanitize=address,undefined \
    -Db_lundef=false --buildtype=debugoptimized \
    -Dc_args=-fno-sanitize-recover=all -Dcpp_args=-fno-sanitize-recover=all >/dev/null || exit 1
fi
targets=()
for src in tests/fuzz/fuzz_*.c; do
  t=$(basename "$src" .c)
  [ "$t" = fuzz_replay ] && continue
  if [ -n "${CSF_FUZZ_TARGETS:-}" ] && [[ " $CSF_FUZZ_TARGETS " != *" $t "* ]]; then continue; fi
  targets+=("$t")
done
# Only what the fuzzing needs: the targets and csfcal (for the seeds).
ninja -C build-fuzz cli/csfcal "${targets[@]/#/tests/fuzz/}" >/dev/null ||
  { ninja -C build-fuzz cli/csfcal "${targets[@]/#/tests/fuzz/}" | tail -30; exit 1; }
mkdir -p build-fuzz/crashes
rc=0

fresh=build-fuzz/fresh-seeds
rm -rf "$fresh"
if [ "${CSF_FUZZ_FRESH_SEEDS:-1}" != 0 ]; then
  start=$SECONDS
  # A failed step is a finding in itself (csfcal could not write its own formats), but the
  # fuzzing goes on with whatever seeds there are.
  if ! bash tests/fuzz/gen-seeds.sh build-fuzz/cli/csfcal "$fresh"; then
    echo "fuzz: seed generation FAILED (above)"; rc=1
  fi
  echo "fuzz: seeds generated in $((SECONDS - start)) s"
fi

# libFuzzer's "#N INITED|DONE cov: E ft: F ..." line: prints "E F" (0 0 if absent).
stat_line() { grep -E "^#[0-9]+[[:space:]]+$2[[:space:]]" "$1" | tail -1 | sed -E 's/.* cov: ([0-9]+) ft: ([0-9]+).*/\1 \2/' |
              grep -E '^[0-9]+ [0-9]+$' || echo "0 0"; }
stats=build-fuzz/fuzz-stats.tsv
printf 'target\tseeds\tfresh\texecs\tcov_seeds\tft_seeds\tcov_end\tft_end\tresult\n' >"$stats"
for t in "${targets[@]}"; do
  bin="build-fuzz/tests/fuzz/$t"
  [ -x "$bin" ] || { echo "fuzz: $t not built"; rc=1; continue; }
  work=$(mktemp -d)
  cp -r "$corpus/$t/." "$work/" 2>/dev/null || true
  n_fresh=0
  if [ -d "$fresh/$t" ]; then
    cp -r "$fresh/$t/." "$work/"; n_fresh=$(find "$fresh/$t" -type f | wc -l)
  fi
  n_seeds=$(find "$work" -type f | wc -l)
  # Large enough for the largest real seed (a plot PNG), so no seed is cut short.
  biggest=$(find "$work" -type f -printf '%s\n' | sort -n | tail -1)
  max_len=$(( ${biggest:-0} > 65536 ? biggest : 65536 ))
  log="build-fuzz/$t.log"
  # -close_fd_mask=3: the targets' own messages (every refused value says why) would flood
  # the log; libFuzzer and the sanitizers keep reporting on a duplicate of stderr.
  "$bin" -max_total_time="$secs" -max_len="$max_len" $seed_opt -print_final_stats=1 -close_fd_mask=3 \
    -artifact_prefix=build-fuzz/crashes/"$t"- "$work" >"$log" 2>&1
  status=$?
  execs=$(grep -oE '^stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' | tail -1)
  read -r cov0 ft0 < <(stat_line "$log" INITED)
  read -r cov1 ft1 < <(stat_line "$log" DONE)
  # A run that stopped on a finding has no DONE line: its last progress line counts.
  [ "$cov1" = 0 ] && read -r cov1 ft1 < <(grep -E '^#[0-9]+[[:space:]]' "$log" | tail -1 |
    sed -E 's/.* cov: ([0-9]+) ft: ([0-9]+).*/\1 \2/' | grep -E '^[0-9]+ [0-9]+$' || echo "0 0")
  summary="$n_seeds seeds ($n_fresh fresh), ${execs:-0} execs in ${secs} s, cov $cov0 -> $cov1 edges, ft $ft0 -> $ft1"
  # A sanitizer report whose process still exited 0 (a recoverable check) fails too.
  if [ $status -eq 0 ] && ! grep -qE 'runtime error:|ERROR: (Address|Undefined|Leak)Sanitizer' "$log"; then
    echo "fuzz: $t ok: $summary"; result=ok
  else
    echo "fuzz: $t FAILED (exit $status; see $log): $summary"
    grep -E 'runtime error:|ERROR: ' "$log" | head -5
    tail -40 "$log"; rc=1; result=FAILED
  fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$t" "$n_seeds" "$n_fresh" "${execs:-0}" \
    "$cov0" "$ft0" "$cov1" "$ft1" "$result" >>"$stats"
  rm -rf "$work"
done
exit $rc
