#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang, AddressSanitizer +
# UndefinedBehaviorSanitizer, MF_FUZZ=ON) into build-fuzz and runs each for
# SECONDS (default 60), at most two at a time, under `nice -n 15`.
#   scripts/fuzz.sh [SECONDS] [TARGET...]        (make fuzz FUZZ_SECONDS=...)
# Each target starts from its committed seeds (fuzz/corpus/<target>/) and
# writes what it finds to build-fuzz/fuzz-work/<target>/ (the corpus it grew)
# and build-fuzz/fuzz-artifacts/<target>/ (crash-*, oom-*, timeout-* inputs),
# never to the committed corpus. A summary with the executions and exec/s of
# each run is printed at the end and kept in build-fuzz/fuzz-summary.txt.
# Environment: FUZZ_BUILD (build-fuzz), FUZZ_JOBS (2), CC/CXX (clang-14).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET=${1:-60}
shift || true
BUILD=${FUZZ_BUILD:-build-fuzz}
JOBS=${FUZZ_JOBS:-2}
ALL_TARGETS=(fuzz_bvh fuzz_gltf fuzz_fbx fuzz_jsonl fuzz_path_csv fuzz_constraints fuzz_model_file fuzz_capi_motion fuzz_capi_inbetween)
TARGETS=("${ALL_TARGETS[@]}")
[ $# -gt 0 ] && TARGETS=("$@")

if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  CC=${CC:-clang-14} CXX=${CXX:-clang++-14} cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DMF_FUZZ=ON
fi
source scripts/sanitizers/env.sh
nice -n 15 cmake --build "$BUILD" -j 2 --target mf_fuzz_all

# The dictionary of a target, if there is one.
dict_of() {
  case "$1" in
    fuzz_bvh) echo fuzz/dict/bvh.dict ;;
    fuzz_jsonl | fuzz_constraints) echo fuzz/dict/json.dict ;;
    fuzz_gltf) echo fuzz/dict/gltf.dict ;;
    fuzz_path_csv) echo fuzz/dict/csv.dict ;;
  esac
}

run_one() {
  local t=$1 work="$BUILD/fuzz-work/$1" art="$BUILD/fuzz-artifacts/$1/" log="$BUILD/fuzz-logs/$1.log"
  mkdir -p "$work" "$art" "$(dirname "$log")"
  local dict_flag=()
  local d
  d=$(dict_of "$t")
  [ -n "$d" ] && dict_flag=(-dict="$d")
  # -rss_limit_mb / -malloc_limit_mb: an input that makes the library allocate
  # more than 2 GB is a finding (the loaders promise to allocate no more than
  # the input justifies). -timeout: one input taking 10 s is a finding.
  nice -n 15 "$BUILD/fuzz/$t" -max_total_time="$SECONDS_PER_TARGET" -rss_limit_mb=2560 -malloc_limit_mb=2048 \
    -timeout=10 -print_final_stats=1 -artifact_prefix="$art" "${dict_flag[@]}" "$work" "fuzz/corpus/$t" \
    >"$log" 2>&1 || echo "$t: stopped with a finding (see $log and $art)"
}

running=0
for t in "${TARGETS[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$JOBS" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait || true

{
  printf '%-22s %14s %10s %8s %s\n' target executions exec/s seconds result
  for t in "${TARGETS[@]}"; do
    log="$BUILD/fuzz-logs/$t.log"
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | awk '{print $2}')
    speed=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | tail -1 | awk '{print $2}')
    result=ok
    grep -qE '^==[0-9]+==ERROR|^SUMMARY|deadly signal|fuzz check failed|out-of-memory|timeout after' "$log" && result=FINDING
    printf '%-22s %14s %10s %8s %s\n' "$t" "${execs:-?}" "${speed:-?}" "$SECONDS_PER_TARGET" "$result"
  done
} | tee "$BUILD/fuzz-summary.txt"
