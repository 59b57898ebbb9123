#!/usr/bin/env bash
# The mixed training set of the shipped two-stage transformer (docs/MODEL_CARD.md,
# "How the models were trained"): the Bandai Namco training archive beside the
# training part of the foreign capture (bench/foreign_data.h; never its
# validation part) retargeted onto the model's rig by build/bench/foreign-training-set.
# The 16 CMU training clips are written three times (so that about 10 % of the
# frames are foreign), and of the ReActIdle standing-idle clips only the acted
# takes 003, 007, 008 and 009 (so that idle does not crowd out motion).
#   scripts/make-mixed-data.sh [OUT]      OUT: .cache/mixed-small
# Needs `make build` (foreign-training-set) and the default model (its rig
# anatomy retargets the clips). The folder is data: it stays out of git.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-.cache/mixed-small}
ARCHIVE=${MF_TRAIN_ARCHIVE:-../shared/data/bandai-namco/train.tar.xz}
if [ -e "$OUT" ]; then
  echo "make-mixed-data: $OUT exists; remove it first" >&2
  exit 1
fi
mkdir -p "$OUT/bandai" "$OUT/foreign"
tar -xJf "$ARCHIVE" -C "$OUT/bandai"
all=$(mktemp -d)
trap 'rm -rf "$all"' EXIT
build/bench/foreign-training-set --out "$all"
for f in "$all"/foreign-cmu-*.bvh; do
  b=$(basename "$f")
  cp "$f" "$OUT/foreign/$b"
  cp "$f" "$OUT/foreign/copy2-$b"
  cp "$f" "$OUT/foreign/copy3-$b"
done
for take in 003 007 008 009; do
  cp "$all/foreign-reactidle-${take}_acted.bvh" "$OUT/foreign/"
done
echo "make-mixed-data: $(find "$OUT" -name '*.bvh' | wc -l) clips in $OUT"
