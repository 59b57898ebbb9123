#!/usr/bin/env bash
# glTF output of the motionfield CLI checked by the Khronos glTF validator
# (scripts/gltf-validate.js; installed by scripts/install-gltf-validator.sh):
# the demo's main output (scripts/demo.sh) exported with `motionfield export`
# as .glb and .gltf, and task and batch outputs named OUT.glb / OUT.gltf, must
# have 0 errors; a damaged file must have errors (the check can fail). Then the
# CLI's errors for bad glTF outputs: an unwritable path, a BVH without frames or
# with a non-finite number (exit 2, a message, no file).
#   usage: gltf_validator_test.sh MOTIONFIELD SOURCE_DIR BUILD_DIR TOOLS_PREFIX WORK_DIR
set -euo pipefail

MF=$1 ROOT=$2 BUILD=$3 TOOLS=$4 WORK=$5
SAMPLE="$ROOT/samples/walk_keyframes.bvh"
validate() { node "$ROOT/scripts/gltf-validate.js" "$TOOLS" "$@"; }
fail() { echo "FAIL: $*" >&2; exit 1; }

rm -rf "$WORK"
mkdir -p "$WORK"

# The demo pipeline, then its main output exported (the metres come from the detected centimetres).
bash "$ROOT/scripts/demo.sh" "$BUILD" "$WORK/demo"
"$MF" --quiet export "$WORK/demo/walk_inbetween.bvh" "$WORK/walk_inbetween.glb"
"$MF" --quiet export "$WORK/demo/walk_inbetween.bvh" "$WORK/walk_inbetween.gltf"
# Task outputs straight to glTF.
"$MF" --quiet fill --in "$SAMPLE" --gap 20:40 --method interp -o "$WORK/walk_fill.glb"
"$MF" --quiet resample -i "$SAMPLE" --fps 60 --method interp --out "$WORK/walk_60fps.gltf"
printf '{"task": "inbetween", "in": "%s", "out": "%s", "keyframes": [0, 30, 60], "method": "interp"}\n' \
  "$SAMPLE" "$WORK/walk_batch.glb" > "$WORK/jobs.jsonl"
"$MF" --quiet batch "$WORK/jobs.jsonl"
[ "$(head -c 4 "$WORK/walk_fill.glb")" = glTF ] || fail "walk_fill.glb is not binary glTF"
grep -q '"asset"' "$WORK/walk_60fps.gltf" || fail "walk_60fps.gltf is not glTF JSON"
validate "$WORK/walk_inbetween.glb" "$WORK/walk_inbetween.gltf" "$WORK/walk_fill.glb" "$WORK/walk_60fps.gltf" \
  "$WORK/walk_batch.glb"

# The validator sees a damaged file (a time out of its declared bounds).
sed 's/"max": *\[/"max": [-1.0, /' "$WORK/walk_60fps.gltf" > "$WORK/damaged.gltf"
if validate "$WORK/damaged.gltf" > "$WORK/damaged.txt"; then fail "the validator found no error in damaged.gltf"; fi
head -n 2 "$WORK/damaged.txt"

# Bad outputs and inputs: exit code 2, a message naming the problem, no file.
expect_error() {  # expect_error TEXT COMMAND...
  local text=$1 status=0
  shift
  "$@" 2> "$WORK/stderr" || status=$?
  [ "$status" -eq 2 ] || fail "exit code $status (expected 2) for: $* ($(cat "$WORK/stderr"))"
  grep -qF -- "$text" "$WORK/stderr" || fail "no '$text' in the message of: $* ($(cat "$WORK/stderr"))"
}
expect_error "does not exist" "$MF" export "$SAMPLE" "$WORK/no/such/dir/out.glb"
mkdir -p "$WORK/ro" && chmod a-w "$WORK/ro"
if [ "$(id -u)" -ne 0 ]; then expect_error "cannot write" "$MF" export "$SAMPLE" "$WORK/ro/out.glb"; fi
expect_error "cannot write /proc/motionfield-test.glb" "$MF" export "$SAMPLE" /proc/motionfield-test.glb  # even as root
expect_error "it is a directory" "$MF" export "$SAMPLE" "$WORK/ro"
awk '/^Frames:/ { print "Frames: 0"; next } { print } /^Frame Time:/ { exit }' "$SAMPLE" > "$WORK/empty.bvh"
expect_error "Frames: 0 must be at least 1" "$MF" export "$WORK/empty.bvh" "$WORK/empty.glb"
awk 'f == 1 { $4 = "nan"; f = 2 } /^Frame Time:/ { f = 1 } { print }' "$SAMPLE" > "$WORK/nan.bvh"
expect_error "non-finite value" "$MF" export "$WORK/nan.bvh" "$WORK/nan.glb"
expect_error "non-finite value" "$MF" fill --in "$WORK/nan.bvh" --gap 20:40 --method interp -o "$WORK/nan_fill.gltf"
for f in no ro/out.glb empty.glb nan.glb nan_fill.gltf; do [ ! -e "$WORK/$f" ] || fail "$f was written"; done
echo "gltf_validator_test: ok"
