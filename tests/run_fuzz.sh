#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang, ASan + UBSan) in
# build-fuzz and runs each for SECONDS on a copy of its seed corpus (the
# checked-in seeds are never changed). A crash, leak, sanitizer report or
# time-out stops the run with the input saved as build-fuzz/TARGET-crash-*.
# The mutations follow $FUZZ_SEED (default 1), so that a run is repeatable:
# CI explores the same inputs every time (as far as its budget reaches);
# set another seed, or FUZZ_SEED=0 (random), to explore further.
# usage: tests/run_fuzz.sh [SECONDS per target, default 25] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-25}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_args fuzz_session fuzz_cmdb_bytes fuzz_cmdb_rows fuzz_commands fuzz_files fuzz_api)
CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCELLMAP_FUZZ=ON > /dev/null
cmake --build build-fuzz -j "$(nproc)" > /dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for t in "${targets[@]}"; do
  mkdir "$work/$t"
  cp tests/fuzz/corpus/$t/* "$work/$t/"
  extra=()
  [ "$t" = fuzz_cmdb_bytes ] && extra=("$PWD/tests/data") # the version 3 and 4 files, read only
  # corpus paths are absolute: fuzz_session works in a directory of its own
  ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$PWD/tests/lsan.supp:print_suppressions=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "build-fuzz/tests/fuzz/$t" -seed="${FUZZ_SEED:-1}" -max_total_time="$secs" -timeout=20 -rss_limit_mb=4096 \
      -close_fd_mask=3 -artifact_prefix="$PWD/build-fuzz/$t-" -print_final_stats=1 \
      "$work/$t" "${extra[@]}" 2> "$work/$t.log" || { tail -60 "$work/$t.log"; exit 1; }
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$t.log")
  echo "$t: $runs inputs in $secs s, nothing found"
done
