#!/usr/bin/env bash
# Jobs per second of one batch file run by `motionfield batch --jobs 1|2` and by
# `python3 -m motionfield.dask --workers 1|2` (docs/BENCHMARKS.md, "More than one
# machine: batch on Dask"). Every run uses 1 intra-op thread per job (--threads 1)
# and the Dask workers 1 thread each; the wall time includes starting the process,
# loading the model and, for Dask, starting the local cluster. Every run's outputs
# are checked to be byte-identical to `motionfield batch --jobs 1`'s. Each command
# also runs the file's first job alone: its wall time is the fixed cost (start-up,
# model load, one job), and (N - 1) / (wall - that) the rate once started.
#   usage: bash bench/dask_batch.sh [BUILD_DIR] [JOBS]    (default: build 16)
set -euo pipefail

SRC=$(cd "$(dirname "$0")/.." && pwd)
BUILD=$(cd "${1:-$SRC/build}" && pwd)
N=${2:-16}
MF="$BUILD/cli/motionfield"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/mf-dask-bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT

cp "$SRC/samples/walk_keyframes.bvh" "$TMP/walk.bvh"
# N in-betweening jobs with the default method (nemf-detail with the bundled
# model) on the 61-frame sample, each with its own keyframes.
for ((i = 0; i < N; ++i)); do
  printf '{"id": "job%d", "task": "inbetween", "in": "walk.bvh", "out": "out/%d.bvh", "keyframes": [0, %d, %d, 60]}\n' \
    "$i" "$i" $((10 + i)) $((35 + i))
done >"$TMP/jobs.jsonl"

export MOTIONFIELD_LIBRARY="$BUILD/capi/libmotionfield.so" PYTHONPATH="$SRC/python" PYTHONDONTWRITEBYTECODE=1

head -n 1 "$TMP/jobs.jsonl" >"$TMP/one.jsonl"

# seconds NAME FILE COMMAND...: runs COMMAND FILE in $TMP/NAME (a fresh out/), prints its wall time.
seconds() {
  local name=$1 file=$2
  shift 2
  rm -rf "${TMP:?}/$name"
  mkdir -p "$TMP/$name/out"
  cp "$TMP/walk.bvh" "$TMP/$file" "$TMP/$name/"
  local t0 t1
  t0=$(date +%s.%N)
  (cd "$TMP/$name" && "$@" "$file" >/dev/null 2>"$TMP/$name.err") || { cat "$TMP/$name.err" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }'
}

# run NAME COMMAND...: the table row of COMMAND: wall time of the N jobs, of the
# first job alone (start-up, model load and one job), and the rates.
run() {
  local name=$1
  shift
  local one all
  one=$(seconds "$name-one" one.jsonl "$@")
  all=$(seconds "$name" jobs.jsonl "$@")
  if [ "$name" != cli1 ] && ! diff -r "$TMP/cli1/out" "$TMP/$name/out" >/dev/null; then
    echo "$name: outputs differ from motionfield batch --jobs 1's" >&2
    exit 1
  fi
  awk -v n="$N" -v one="$one" -v all="$all" -v what="$* JOBS.jsonl" \
    'BEGIN { printf "| `%s` | %d | %.1f | %.2f | %.1f | %.2f |\n", what, n, all, n / all, one, (n - 1) / (all - one) }' |
    sed "s|$BUILD/capi/||; s|$BUILD/cli/||; s|/usr/bin/||"
}

echo "| command | jobs | wall (s) | jobs/s | 1 job alone (s) | jobs/s after the first |"
echo "|---|---:|---:|---:|---:|---:|"
run cli1 "$MF" --threads 1 batch --jobs 1
run cli2 "$MF" --threads 1 batch --jobs 2
run dask1 /usr/bin/python3 -m motionfield.dask --workers 1 --threads 1
run dask2 /usr/bin/python3 -m motionfield.dask --workers 2 --threads 1
echo "(every run's outputs byte-identical to the first's; load average $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores)"
