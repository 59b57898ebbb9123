#!/usr/bin/env bash
# Runs a sample (samples/c/inbetween.c, samples/cpp/inbetween.cc: the same
# job) on the bundled clip and checks its report and its output BVH: 61
# frames, the input's frame time and hierarchy.
#   usage: run_sample.sh SAMPLE_EXECUTABLE SOURCE_DIR
set -euo pipefail
exe=$1
src=$2
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mf-sample.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
"$exe" "$src/samples/walk_keyframes.bvh" "$tmp/out.bvh" | tee "$tmp/log"
grep -q '^method: ' "$tmp/log"
grep -q '^model: ' "$tmp/log"
frames=$(awk '/^Frames:/ { print $2 }' "$tmp/out.bvh")
[ "$frames" = 61 ] || { echo "expected 61 frames, got $frames"; exit 1; }
grep -q '^Frame Time: 0.0333333333' "$tmp/out.bvh" || { echo "frame time not kept"; exit 1; }
diff <(sed '/^MOTION/q' "$src/samples/walk_keyframes.bvh") <(sed '/^MOTION/q' "$tmp/out.bvh") \
  || { echo "hierarchy not kept"; exit 1; }
echo "sample ok"
