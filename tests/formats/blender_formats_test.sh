#!/usr/bin/env bash
# glTF and FBX files exported by Blender (Debian's 3.4) from the sample BVH
# read back to the BVH's motion (compare_motion.py: 1e-4 of the BVH's unit,
# 1e-3 degrees), through every client: the CLI's commands (rig, inbetween,
# export, transition, batch) on a Mixamo-style rig ("mixamorig:" names), Python, and the
# outputs checked by the Khronos glTF validator. Skipped (77) without Blender.
#   usage: blender_formats_test.sh MOTIONFIELD SOURCE_DIR TOOLS_PREFIX WORK_DIR
set -euo pipefail

MF=$1 ROOT=$2 TOOLS=$3 WORK=$4
SAMPLE="$ROOT/samples/walk_keyframes.bvh"
MODEL="$ROOT/models/motionfield-prior.mfm"
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v blender >/dev/null 2>&1 || { echo "blender is not installed: skipped"; exit 77; }

rm -rf "$WORK"
mkdir -p "$WORK"
export_with_blender() {  # OUTDIR [PREFIX]
  blender --background --factory-startup --python-exit-code 1 --python "$ROOT/tests/formats/blender_export.py" \
    -- "$SAMPLE" "$@" > "$1.log" 2>&1 || { cat "$1.log"; fail "blender could not export $1"; }
}
export_with_blender "$WORK/plain"
export_with_blender "$WORK/mixamo" "mixamorig:"

compare() { /usr/bin/python3 "$ROOT/tests/formats/compare_motion.py" "$SAMPLE" "$@"; }
for f in blender.fbx blender_zup.fbx blender.glb; do
  compare "$WORK/plain/$f"
  compare "$WORK/mixamo/$f" "mixamorig:"
done
# Our own glTF output reads back too.
"$MF" --quiet export "$SAMPLE" "$WORK/walk.glb"
compare "$WORK/walk.glb"

# A Mixamo-style FBX and glTF through rig and inbetween; glTF and BVH outputs.
for f in blender.fbx blender.glb; do
  "$MF" --model "$MODEL" rig "$WORK/mixamo/$f" > "$WORK/rig-$f.txt"
  grep -q "mixamorig:Hips" "$WORK/rig-$f.txt" || { cat "$WORK/rig-$f.txt"; fail "rig does not list mixamorig:Hips for $f"; }
  grep -q "(from the file;" "$WORK/rig-$f.txt" || { cat "$WORK/rig-$f.txt"; fail "rig does not say the unit is the file's"; }
  "$MF" --quiet --model "$MODEL" inbetween --in "$WORK/mixamo/$f" --keyframes 0,30,60 -o "$WORK/inbetween-$f.glb"
  "$MF" --quiet --model "$MODEL" fill --in "$WORK/mixamo/$f" --gap 20:40 --method interp -o "$WORK/fill-$f.bvh"
  grep -q "mixamorig:Hips" "$WORK/fill-$f.bvh" || fail "the BVH written from $f lost the joint names"
done
# A transition from Blender's FBX into Blender's glTF of the same rig.
"$MF" --quiet --model "$MODEL" transition "$WORK/mixamo/blender.fbx" "$WORK/mixamo/blender.glb" --frames 10 \
  --method interp -o "$WORK/transition.glb" || fail "transition from FBX into glTF"
# The batch, with the animation named by index; an animation that is not there.
printf '{"task": "resample", "in": "%s", "out": "%s", "fps": 60, "method": "interp", "animation": 0}\n' \
  "$WORK/mixamo/blender_zup.fbx" "$WORK/batch.glb" > "$WORK/jobs.jsonl"
"$MF" --quiet batch "$WORK/jobs.jsonl"
set +e
"$MF" --quiet --animation 3 export "$WORK/plain/blender.glb" "$WORK/none.glb" 2> "$WORK/err.txt"
code=$?
set -e
[ "$code" = 2 ] || fail "a missing animation exits with $code, not 2"
grep -q "there is no animation 3" "$WORK/err.txt" || { cat "$WORK/err.txt"; fail "no message for a missing animation"; }
[ ! -e "$WORK/none.glb" ] || fail "an output was written for a missing animation"

# A truncated FBX: exit 2, a message naming the file.
head -c 5000 "$WORK/plain/blender.fbx" > "$WORK/truncated.fbx"
set +e
"$MF" --quiet export "$WORK/truncated.fbx" "$WORK/truncated.glb" 2> "$WORK/err.txt"
code=$?
set -e
[ "$code" = 2 ] || fail "a truncated FBX exits with $code, not 2"
grep -q "truncated.fbx" "$WORK/err.txt" || { cat "$WORK/err.txt"; fail "the error does not name the file"; }
cat "$WORK/err.txt"

# Python reads them too, the animation by name.
PYTHONPATH="$ROOT/python" /usr/bin/python3 - "$WORK/mixamo/blender.glb" <<'PY'
import sys
import motionfield as mf
m = mf.Motion.load(sys.argv[1], fps=60)
assert m.frame_count == 121 and m.fps == 60, (m.frame_count, m.fps)
try:
    mf.Motion.load(sys.argv[1], animation="no such animation")
    raise SystemExit("no error for a missing animation")
except mf.InvalidArgumentError as e:
    assert "no animation named 'no such animation'" in str(e), str(e)
PY

if [ -f "$TOOLS/node_modules/gltf-validator/package.json" ]; then
  node "$ROOT/scripts/gltf-validate.js" "$TOOLS" "$WORK"/inbetween-*.glb "$WORK/batch.glb" "$WORK/transition.glb"
else
  fail "the glTF validator is not installed in $TOOLS (the gltf_validator_install test installs it)"
fi
echo "ok"
