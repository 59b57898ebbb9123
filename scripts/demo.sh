#!/usr/bin/env bash
# The README's demo (`make demo`): in-betweening and resampling of the bundled,
# hand-made sample clip samples/walk_keyframes.bvh with the motionfield CLI.
#   usage: scripts/demo.sh BUILD_DIR OUT_DIR
# Both run the default methods with the bundled models (models/): in-betweening
# with the latent solver started from the two-stage transformer ("nemf-detail"),
# resampling with the prior ("prior"); without a model, interpolation. Input
# keyframes come out exactly (docs/BENCHMARKS.md). --verbose names the method
# that ran and its timings.
set -euo pipefail

if [ $# -ne 2 ]; then
  echo "usage: $0 BUILD_DIR OUT_DIR" >&2
  exit 2
fi
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
MF="$1/cli/motionfield"
OUT="$2"
SAMPLE="$ROOT/samples/walk_keyframes.bvh"

if [ ! -x "$MF" ]; then
  echo "demo: $MF not found; build first (make build)" >&2
  exit 1
fi
mkdir -p "$OUT"

frames=$(awk '/^Frames:/ { print $2; exit }' "$SAMPLE")
fps=$(awk '/^Frame Time:/ { printf "%g", 1 / $3; exit }' "$SAMPLE")
# Every 10th frame, and the last.
keyframes=$(seq -s, 0 10 $((frames - 1)))
if [ $(((frames - 1) % 10)) -ne 0 ]; then keyframes="$keyframes,$((frames - 1))"; fi

echo "demo: sample $SAMPLE ($frames frames at $fps fps)"
"$MF" --verbose inbetween --in "$SAMPLE" --keyframes "$keyframes" --out "$OUT/walk_inbetween.bvh"
echo "demo: in-betweened from keyframes $keyframes -> $OUT/walk_inbetween.bvh"
"$MF" --verbose resample --in "$SAMPLE" --fps 60 --out "$OUT/walk_60fps.bvh"
echo "demo: resampled to 60 fps ($(awk '/^Frames:/ { print $2; exit }' "$OUT/walk_60fps.bvh") frames) -> $OUT/walk_60fps.bvh"
echo "demo: done; open the .bvh files in $OUT in any BVH viewer, e.g. Blender with the motionfield add-on: File > Import > Motion (motionfield) (Blender 3.4.1's own BVH importer fails on Python 3.11); lengths are in centimetres, Y up"
