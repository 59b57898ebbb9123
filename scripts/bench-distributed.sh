#!/usr/bin/env bash
# Data-parallel training benchmark (docs/BENCHMARKS.md, "More than one machine:
# training"): trains the prior at its pilot size (decoder 6 x 256, z_l 256,
# z_g 64; docs/PRIOR_SIZES.md) with the same global batch of 32 windows
#   - 1 process, --batch 32, 1 thread
#   - 2 processes on loopback, --batch 16 each, 1 thread each
# for MINUTES of wall time each (the same budget, hence the same schedule), then
# prints a Markdown table: steps, steps per second (training and validation
# together, from log.csv) and the minutes until the validation score first
# reached TARGET (default: the larger of the two runs' best scores, which both
# reached).
#
#   scripts/bench-distributed.sh [MINUTES=8] [BUILD=build] [OUT=/tmp/mf-bench-distributed] [TARGET]
#
# Environment: CLIPS (training clips used, default 300: short epochs so that the
# validation score is measured often), PORT (default 29517).
set -euo pipefail
minutes=${1:-8}
build=${2:-build}
out=${3:-/tmp/mf-bench-distributed}
target=${4:-}
clips=${CLIPS:-300}
port=${PORT:-29517}
trainer="$build/training/motionfield-train"
[ -x "$trainer" ] || { echo "bench-distributed: $trainer not built" >&2; exit 2; }

common=(prior --width 256 --layers 6 --zl 256 --zg 64 --max-train-clips "$clips" --max-minutes "$minutes"
        --threads 1 --seed 1 --quiet)
rm -rf "$out"
mkdir -p "$out"

echo "bench-distributed: 1 process, batch 32 ($minutes min)" >&2
"$trainer" "${common[@]}" --batch 32 --out "$out/one" > "$out/one.log" 2>&1

echo "bench-distributed: 2 processes, batch 16 each ($minutes min)" >&2
group=(--world-size 2 --master "127.0.0.1:$port" --dist-timeout 300)
"$trainer" "${common[@]}" --batch 16 "${group[@]}" --rank 1 --out "$out/two-rank1" > "$out/two-rank1.log" 2>&1 &
rank1=$!
"$trainer" "${common[@]}" --batch 16 "${group[@]}" --rank 0 --out "$out/two" > "$out/two.log" 2>&1
wait "$rank1"

# Columns of log.csv: 1 epoch, 2 step, 3 minutes, ..., last: val_score.
best() { awk -F, 'NR > 1 { if (b == "" || $NF < b) b = $NF } END { print b }' "$1/log.csv"; }
if [ -z "$target" ]; then
  target=$(printf '%s\n%s\n' "$(best "$out/one")" "$(best "$out/two")" | sort -g | tail -1)
fi
row() {  # name, run folder
  awk -F, -v name="$1" -v target="$target" '
    NR == 2 { s0 = $2; m0 = $3 }
    NR > 1 { s = $2; m = $3; e = $1; if (reach == "" && $NF <= target) reach = $3; if (b == "" || $NF < b) b = $NF }
    END {
      rate = (m > m0) ? (s - s0) / ((m - m0) * 60) : 0
      printf "| %s | %d | %d | %.1f | %.3f | %.4f | %s |\n", name, e, s, m, rate, b, (reach == "" ? "not reached" : sprintf("%.1f", reach))
    }' "$2/log.csv"
}
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| run | epochs | steps | minutes | steps/s (after epoch 1) | best val score | minutes to val score <= $target |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"
row "1 process, batch 32" "$out/one"
row "2 processes, batch 16 each" "$out/two"
