#!/usr/bin/env bash
# The README's demo (`make demo`): in-betweening and resampling of the bundled,
# hand-made sample clip samples/walk_keyframes.bvh with the motionfield CLI.
#   usage: scripts/demo.sh BUILD_DIR OUT_DIR
# Both use the bundled prior (models/motionfield-prior.mfm) through the default
# methods: in-betweening with the latent solver ("nemf"), resampling with
# "prior"; input keyframes come out exactly (docs/BENCHMARKS.md).
set -euo pipefail

if [ $# -ne 2 ]; then
  echo "usage: $0 BUILD_DIR OUT_DIR" >&2
  exit 2
fi
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
MF="$1/capi/motionfield"
OUT="$2"
SAMPLE="$ROOT/samples/walk_keyframes.bvh"
MODEL="$ROOT/models/motionfield-prior.mfm"

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
inbetween_method=interp
if [ -f "$MODEL" ]; then inbetween_method=nemf; fi
"$MF" inbetween --in "$SAMPLE" --keyframes "$keyframes" --method "$inbetween_method" --out "$OUT/walk_inbetween.bvh"
echo "demo: in-betweened from keyframes $keyframes with method '$inbetween_method' -> $OUT/walk_inbetween.bvh"
resample_method=interp
if [ -f "$MODEL" ]; then resample_method=prior; fi
"$MF" resample --in "$SAMPLE" --fps 60 --method "$resample_method" --out "$OUT/walk_60fps.bvh"
echo "demo: resampled to 60 fps with method '$resample_method' ($(awk '/^Frames:/ { print $2; exit }' "$OUT/walk_60fps.bvh") frames) -> $OUT/walk_60fps.bvh"
echo "demo: done; open the .bvh files in $OUT in any BVH viewer, e.g. Blender: File > Import > Motion Capture (.bvh); lengths are in centimetres, Y up"
