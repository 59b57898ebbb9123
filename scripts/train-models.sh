#!/usr/bin/env bash
# Trains every shipped model of models/ from scratch with the project's trainer
# (build/training/motionfield-train), in the order and with the options that
# produced the shipped files (docs/MODEL_CARD.md, "How the models were trained").
#
#   scripts/train-models.sh [--build DIR] [--out DIR] [--checkpoints DIR] [--data PATH]
#                           [--cache-dir DIR] [--threads N] [--jobs 1|2] [--smoke] [--fresh]
#                           [--replace-shipped] [--dry-run]
#
# Stages run one after another (--jobs 2: the prior's chain and the in-betweeners'
# chain side by side, one core each). Each stage trains into DIR/<stage>/ of the
# checkpoint folder (default checkpoints/, git-ignored) and is marked done by
# DIR/<stage>.done when it finishes. Re-running the same command skips the done
# stages and continues an interrupted one from its last checkpoint (the trainer's
# --resume; its --max-minutes budget counts the earlier part). At the end the
# five model files are copied into the output folder (default out/models/). The
# output folder is never models/ unless --replace-shipped is given.
#
# --smoke runs every stage for a few steps on a slice of the data (the 17
# "normal"-style clips of dataset 1 from the archive, or a folder's first 30
# BVH files, copied into the checkpoint folder) and writes models of the
# shipped sizes; default checkpoint folder checkpoints/smoke/, default output
# out/models-smoke/. It is the CTest test train_models_smoke (tests/CMakeLists.txt).
# --fresh deletes the checkpoint folder first. --dry-run prints the commands.
#
# Exit codes: 0 done; a failed stage's own (1, or 2 for bad input); 2 bad
# arguments or no trainer binary; 77 no training data (the archive is missing;
# CTest counts it as skipped).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)
BUILD=$ROOT/build
OUT=""
CK=""
DATA=$ROOT/../shared/data/bandai-namco/train.tar.xz
CACHE=""
THREADS=1
JOBS=1
SMOKE=0
FRESH=0
REPLACE=0
DRY=0

usage() { sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed -e '$d' -e 's/^# \{0,1\}//'; }
die() { echo "train-models: $*" >&2; exit 2; }

while (($#)); do
  case $1 in
    --build) BUILD=${2:?}; shift ;;
    --out) OUT=${2:?}; shift ;;
    --checkpoints) CK=${2:?}; shift ;;
    --data) DATA=${2:?}; shift ;;
    --cache-dir) CACHE=${2:?}; shift ;;
    --threads) THREADS=${2:?}; shift ;;
    --jobs) JOBS=${2:?}; shift ;;
    --smoke) SMOKE=1 ;;
    --fresh) FRESH=1 ;;
    --replace-shipped) REPLACE=1 ;;
    --dry-run) DRY=1 ;;
    -h|--help) usage; exit 0 ;;
    *) die "unknown argument '$1' (--help lists them)" ;;
  esac
  shift
done
[[ $JOBS == 1 || $JOBS == 2 ]] || die "--jobs is 1 or 2"
[[ $THREADS =~ ^[1-9][0-9]*$ ]] || die "--threads takes a positive number"

if ((SMOKE)); then
  : "${CK:=$ROOT/checkpoints/smoke}"
  : "${OUT:=$ROOT/out/models-smoke}"
else
  : "${CK:=$ROOT/checkpoints}"
  : "${OUT:=$ROOT/out/models}"
fi

TRAIN=$BUILD/training/motionfield-train
if [[ ! -e $DATA ]]; then
  echo "train-models: no training data at $DATA (the Bandai Namco archive, see docs/MODEL_CARD.md): skipped" >&2
  exit 77
fi
((DRY)) || [[ -x $TRAIN ]] || die "no trainer at $TRAIN: build it first (make build, or --build DIR)"

OUT=$(realpath -m "$OUT")
if [[ $OUT == "$(realpath -m "$ROOT/models")" ]] && ((!REPLACE)); then
  die "the output folder is models/, the shipped models: give --replace-shipped to overwrite them"
fi
CK=$(realpath -m "$CK")
if ((!DRY)); then
  ((FRESH)) && rm -rf "$CK"
  mkdir -p "$CK" "$OUT"
fi

DATA_ARGS=(--data "$DATA")
[[ -n $CACHE ]] && DATA_ARGS+=(--cache-dir "$CACHE")
if ((SMOKE)); then
  # The slice, made once: of the Bandai Namco archive, dataset 1's "normal"
  # style (17 clips: 14 training, 3 validation by the file-name split of
  # prior/data/dataset.h); of a folder, its first 30 BVH files by path.
  SLICE=$CK/data
  if [[ ! -d $SLICE ]] && ((!DRY)); then
    rm -rf "$SLICE.tmp" && mkdir -p "$SLICE.tmp"
    if [[ -d $DATA ]]; then
      mapfile -t clips < <(find "$DATA" -iname '*.bvh' -type f | LC_ALL=C sort)
      ((${#clips[@]})) || die "no BVH files in $DATA"
      cp "${clips[@]:0:30}" "$SLICE.tmp/"
    else
      tar -xJf "$DATA" -C "$SLICE.tmp" --wildcards '*/dataset-1_*_normal_*.bvh'
    fi
    mv "$SLICE.tmp" "$SLICE"
  fi
  DATA_ARGS=(--data "$SLICE" --cache-dir "$CK/cache")
fi

# Smoke options: STEPS optimiser steps of a small batch, few validation windows.
smoke_args() {  # KIND STEPS
  ((SMOKE)) || return 0
  local args=(--max-steps "$2" --batch 4)
  [[ $1 != prior ]] && args+=(--validation-windows 8)
  printf '%s\n' "${args[@]}"
}

# stage NAME DIR KIND [options...]: motionfield-train KIND --out CK/DIR unless
# CK/NAME.done exists. In smoke mode a stage that continues a run in the same
# folder (the two-stage model's second budget) gets twice the steps.
stage() {
  local name=$1 dir=$CK/$2 kind=$3 steps=3
  shift 3
  if [[ -f $CK/$name.done ]]; then
    echo "train-models: $name: done earlier ($dir)"
    return 0
  fi
  [[ $name == twostage-1b ]] && steps=6
  local cmd=("$TRAIN" "$kind" --out "$dir" "${DATA_ARGS[@]}" --threads "$THREADS" --resume "$@")
  local extra
  mapfile -t extra < <(smoke_args "$kind" "$steps")
  cmd+=("${extra[@]}")
  echo "train-models: $name: ${cmd[*]}"
  ((DRY)) && return 0
  local t0=$SECONDS
  "${cmd[@]}"
  touch "$CK/$name.done"
  echo "train-models: $name: $((SECONDS - t0)) s"
}

init() { echo "$CK/$1/best.mfm"; }

# The prior: 750 minutes for the VAE (9 runs, each continuing the last one's
# weights with a lower cosine schedule, the last two with time warp and
# mirroring), then 35 minutes for the default GMP on the VAE's reconstructions,
# the 750-minute GMP kept as the steering GMP.
prior_chain() {
  local common=(--lr-final 1e-5 --kl-warmup 0)
  stage prior-1 prior-1 prior --width 256 --layers 6 --zl 256 --zg 64 --max-minutes 95 --seed 1
  stage prior-2 prior-2 prior --init "$(init prior-1)" --lr 3e-4 "${common[@]}" --max-minutes 105 --seed 2
  stage prior-3 prior-3 prior --init "$(init prior-2)" --lr 2e-4 "${common[@]}" --max-minutes 105 --seed 3
  stage prior-4 prior-4 prior --init "$(init prior-3)" --lr 1.5e-4 "${common[@]}" --max-minutes 90 --seed 4
  stage prior-5 prior-5 prior --init "$(init prior-4)" --lr 1e-4 "${common[@]}" --max-minutes 100 --seed 5
  stage prior-6 prior-6 prior --init "$(init prior-5)" --lr 8e-5 "${common[@]}" --max-minutes 100 --seed 6
  stage prior-7 prior-7 prior --init "$(init prior-6)" --lr 1e-4 "${common[@]}" --max-minutes 75 --seed 8 \
    --speeds 0.8,1.25
  stage prior-8 prior-8 prior --init "$(init prior-7)" --lr 1e-4 "${common[@]}" --max-minutes 80 --seed 11 \
    --mirror --speeds 0.8,1.25
  stage prior-9 prior-9 prior --init "$(init prior-8)" --gmp-only --steering-gmp --gmp-width 128 \
    --gmp-reconstructed 1 --mirror --speeds 0.8,1.25 --lr 3e-4 "${common[@]}" --max-minutes 35 --seed 301
}

# The in-betweeners: the two-stage model (750 minutes over 8 runs, the last two
# with mirroring), CITL (100 minutes), KeyframeNet + RefineNet (120 minutes);
# then the rig anatomy, measured on the data.
inbetweener_chain() {
  local small=(--hp width=64 --hp layers=2 --hp heads=4)
  stage twostage-1a twostage-1 twostage "${small[@]}" --hp ffn=128 --max-minutes 55 --seed 1
  stage twostage-1b twostage-1 twostage "${small[@]}" --hp ffn=128 --max-minutes 120 --seed 1
  stage twostage-2 twostage-2 twostage --init "$(init twostage-1)" --lr 2e-4 --warmup 0.05 --max-minutes 50 --seed 2
  stage twostage-3 twostage-3 twostage --init "$(init twostage-2)" --lr 1.5e-4 --warmup 0.03 --max-minutes 100 --seed 3
  stage twostage-4 twostage-4 twostage --init "$(init twostage-3)" --lr 1e-4 --warmup 0.03 --max-minutes 90 --seed 4
  stage twostage-5 twostage-5 twostage --init "$(init twostage-4)" --lr 8e-5 --warmup 0.03 --max-minutes 100 --seed 5
  stage twostage-6 twostage-6 twostage --init "$(init twostage-5)" --lr 6e-5 --warmup 0.03 --max-minutes 100 --seed 6
  stage twostage-7 twostage-7 twostage --init "$(init twostage-6)" --mirror --lr 1e-4 --warmup 0.03 --max-minutes 80 \
    --seed 11
  stage twostage-8 twostage-8 twostage --init "$(init twostage-7)" --mirror --lr 8e-5 --warmup 0.03 --max-minutes 110 \
    --seed 12
  stage citl citl citl "${small[@]}" --hp ffn=256 --max-minutes 100 --seed 1
  stage keyframe keyframe keyframe --hp width=96 --hp layers=3 --hp heads=4 --hp ffn=192 --max-minutes 120 --seed 1 \
    --validation-windows 128 --validate-minutes 5
  if [[ -f $CK/rig.done ]]; then
    echo "train-models: rig: done earlier"
  else
    local cmd=("$TRAIN" rig --out "$CK/rig/motionfield-rig.json" "${DATA_ARGS[@]}")
    echo "train-models: rig: ${cmd[*]}"
    if ((!DRY)); then
      mkdir -p "$CK/rig"
      "${cmd[@]}"
      touch "$CK/rig.done"
    fi
  fi
}

START=$SECONDS
if ((JOBS == 2 && !DRY)); then
  prior_chain > >(sed -u 's/^/[prior] /') 2>&1 &
  prior_pid=$!
  # A failed in-betweener stage ends the prior's chain too (its trainer first).
  trap 'pkill -TERM -P "$prior_pid" 2>/dev/null; kill "$prior_pid" 2>/dev/null; true' EXIT
  inbetweener_chain
  wait "$prior_pid"
  trap - EXIT
else
  prior_chain
  inbetweener_chain
fi
((DRY)) && exit 0

# The model files, each copied under a temporary name and renamed.
install_model() {  # FROM NAME
  cp "$1" "$OUT/.$2.tmp"
  mv "$OUT/.$2.tmp" "$OUT/$2"
  echo "train-models: $OUT/$2"
}
install_model "$CK/prior-9/best.mfm" motionfield-prior.mfm
install_model "$CK/twostage-8/best.mfm" motionfield-twostage.mfm
install_model "$CK/citl/best.mfm" motionfield-citl.mfm
install_model "$CK/keyframe/best.mfm" motionfield-keyframe.mfm
install_model "$CK/rig/motionfield-rig.json" motionfield-rig.json
echo "train-models: every model trained in $((SECONDS - START)) s"
