#!/usr/bin/env bash
# End-to-end tests of the motionfield CLI on the bundled sample.
#   usage: bash tests/cli_test.sh <path-to-motionfield> <source-dir> <path-to-mf_bvh_diff> [<path-to-mf_capi_tiny_model>]
# Checks frame counts and frame times of every subcommand's output, that known
# frames come back unchanged (with the test tool mf_bvh_diff, tests/tools), the
# exit code 2 of every kind of bad input, and batch mode.
set -u

MF=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SRC=$(cd "$2" && pwd)
DIFF=$(cd "$(dirname "$3")" && pwd)/$(basename "$3")
# The writer of tiny test models (capi/): CTest passes it.
HELPER=${4:-$(dirname "$MF")/mf_capi_tiny_model}
SAMPLE="$SRC/samples/walk_keyframes.bvh"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/mf-cli-test.XXXXXX")
trap 'rm -rf "$TMP"' EXIT

failures=0
checks=0
pass() { checks=$((checks + 1)); }
fail() { checks=$((checks + 1)); failures=$((failures + 1)); echo "FAIL: $*"; }

frames_of() { awk '/^Frames:/ { print $2; exit }' "$1"; }
frame_time_of() { awk '/^Frame Time:/ { print $3; exit }' "$1"; }

# expect_rc CODE DESCRIPTION -- COMMAND...: runs the command, stderr to $TMP/err.
expect_rc() {
  local want=$1 what=$2
  shift 3
  "$@" >"$TMP/out" 2>"$TMP/err"
  local rc=$?
  if [ "$rc" -eq "$want" ]; then pass; else fail "$what: exit code $rc, expected $want"; sed 's/^/  stderr: /' "$TMP/err"; fi
}

expect_frames() {  # FILE COUNT
  local n
  n=$(frames_of "$1")
  if [ "$n" = "$2" ]; then pass; else fail "$1: $n frames, expected $2"; fi
}

expect_frame_time() {  # FILE SECONDS (within 1e-6 relative)
  local t
  t=$(frame_time_of "$1")
  if awk -v a="$t" -v b="$2" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 1e-6 * b) }'; then
    pass
  else
    fail "$1: frame time $t, expected $2"
  fi
}

expect_stderr() {  # PATTERN DESCRIPTION
  if grep -q -- "$1" "$TMP/err"; then pass; else fail "$2: stderr lacks '$1'"; sed 's/^/  stderr: /' "$TMP/err"; fi
}

# in_dir DIR COMMAND...: runs COMMAND (a check) in DIR, in this shell so that
# its pass or failure counts.
in_dir() {
  local dir=$1
  shift
  pushd "$dir" >/dev/null || { fail "cannot enter $dir"; return; }
  "$@"
  popd >/dev/null || exit 1
}

expect_absent() {  # FILE
  if [ -e "$1" ]; then fail "$1 was written although the command failed"; else pass; fi
}

[ -x "$MF" ] || { echo "not executable: $MF"; exit 1; }
[ -x "$DIFF" ] || { echo "not executable: $DIFF"; exit 1; }
[ -f "$SAMPLE" ] || { echo "missing sample: $SAMPLE"; exit 1; }
N=$(frames_of "$SAMPLE")
FT=$(frame_time_of "$SAMPLE")
[ "$N" = 61 ] || fail "sample has $N frames, expected 61"

# ------------------------------------------------------------ help, version
expect_rc 0 "--version" -- "$MF" --version
grep -q "^motionfield [0-9]" "$TMP/out" && pass || fail "--version prints 'motionfield <version>'"
expect_rc 0 "--help" -- "$MF" --help
for cmd in inbetween fill resample renav transition batch rig; do
  expect_rc 0 "$cmd --help" -- "$MF" "$cmd" --help
  grep -q "usage: motionfield $cmd" "$TMP/out" && pass || fail "$cmd --help prints its usage"
done

# ------------------------------------------------------------ inbetween
ALL=$(seq -s, 0 $((N - 1)))
expect_rc 0 "inbetween, every frame a keyframe" -- "$MF" inbetween --in "$SAMPLE" --keyframes "$ALL" --out "$TMP/all.bvh"
expect_frames "$TMP/all.bvh" "$N"
expect_frame_time "$TMP/all.bvh" "$FT"
expect_rc 0 "keeping every frame reproduces the input" -- "$DIFF" "$SAMPLE" "$TMP/all.bvh"

KEYS=0,10,20,30,40,50,60
for method in interp zerovel; do
  expect_rc 0 "inbetween --method $method" -- \
    "$MF" inbetween --in "$SAMPLE" --keyframes "$KEYS" --out "$TMP/kf-$method.bvh" --method "$method"
  expect_frames "$TMP/kf-$method.bvh" "$N"
  expect_frame_time "$TMP/kf-$method.bvh" "$FT"
  expect_rc 0 "inbetween $method keeps the keyframes" -- "$DIFF" "$SAMPLE" "$TMP/kf-$method.bvh" --frames "$KEYS"
  # ...and really changes the others (so the comparison above can fail).
  expect_rc 3 "inbetween $method changes unknown frames" -- "$DIFF" "$SAMPLE" "$TMP/kf-$method.bvh"
done
# --flag=value form, --threads anywhere, and the default method: with the
# bundled model the measured best method (tasks/methods/jobs.cc default_method(),
# docs/BENCHMARKS.md), which keeps the keyframes and is not interpolation;
# without a model interpolation (tests/jobs_test.cc).
if [ -f "$SRC/models/motionfield-prior.mfm" ]; then
  default_method=nemf
  if [ -f "$SRC/models/motionfield-twostage.mfm" ]; then default_method=nemf-detail; fi
  expect_rc 0 "inbetween --in=..." -- \
    "$MF" --threads 1 inbetween --in="$SAMPLE" --keyframes="$KEYS" --out="$TMP/default.bvh"
  expect_frames "$TMP/default.bvh" "$N"
  expect_rc 0 "inbetween --method $default_method" -- \
    "$MF" --threads 1 inbetween --in "$SAMPLE" --keyframes "$KEYS" --out "$TMP/named-default.bvh" --method "$default_method"
  expect_rc 0 "the default method with the model is $default_method" -- \
    "$DIFF" "$TMP/default.bvh" "$TMP/named-default.bvh" --tol 1e-9
  expect_rc 0 "the default method keeps the keyframes" -- "$DIFF" "$SAMPLE" "$TMP/default.bvh" --frames "$KEYS"
  expect_rc 3 "...and is not interp" -- "$DIFF" "$TMP/default.bvh" "$TMP/kf-interp.bvh"
fi

# ------------------------------------------------------------ fill
for method in interp zerovel; do
  expect_rc 0 "fill --method $method" -- "$MF" fill --in "$SAMPLE" --gap 10:40 --out "$TMP/fill-$method.bvh" --method "$method"
  expect_frames "$TMP/fill-$method.bvh" "$N"
  expect_frame_time "$TMP/fill-$method.bvh" "$FT"
  expect_rc 0 "fill $method keeps frames outside the gap" -- \
    "$DIFF" "$SAMPLE" "$TMP/fill-$method.bvh" --frames "$(seq -s, 0 9),$(seq -s, 40 60)"
done
expect_rc 0 "fill with the widest gap" -- "$MF" fill --in "$SAMPLE" --gap 1:60 --out "$TMP/fill-wide.bvh"
expect_frames "$TMP/fill-wide.bvh" "$N"

# ------------------------------------------------------------ transition
# A's frames 0..30, 15 generated frames, B's frames 20..60 (both clips the sample).
expect_rc 0 "transition --place keep" -- "$MF" --json transition "$SAMPLE" "$SAMPLE" -o "$TMP/tr.bvh" \
  --frames 15 --from-frame 30 --to-frame 20 --place keep --method interp
grep -q '"transition":{"frames":15,"first_frame":31}' "$TMP/out" && pass || fail "transition --json reports its frames"
expect_frames "$TMP/tr.bvh" $((31 + 15 + 41))
expect_frame_time "$TMP/tr.bvh" "$FT"
expect_rc 0 "transition keeps A's part" -- "$DIFF" "$SAMPLE" "$TMP/tr.bvh" --frames "$(seq -s, 0 30)"
expect_rc 0 "transition --only-transition" -- "$MF" transition "$SAMPLE" "$SAMPLE" -o "$TMP/tr-only.bvh" \
  --frames 15 --from-frame 30 --to-frame 20 --only-transition --method interp
expect_frames "$TMP/tr-only.bvh" 15
expect_rc 0 "transition with the length chosen" -- "$MF" transition "$SAMPLE" "$SAMPLE" -o "$TMP/tr-auto.bvh" \
  --to-frame 5 --method interp
expect_stderr "the transition has [0-9]* frames (chosen" "the chosen length is reported"
expect_rc 0 "transition --quiet" -- "$MF" --quiet transition "$SAMPLE" "$SAMPLE" -o "$TMP/tr-quiet.bvh" --method interp
[ -s "$TMP/err" ] && fail "transition --quiet printed to stderr" || pass
echo "{\"task\": \"transition\", \"in\": \"$SAMPLE\", \"to\": \"$SAMPLE\", \"out\": \"$TMP/tr-batch.bvh\", \"frames\": 15, \"from_frame\": 30, \"to_frame\": 20, \"place\": \"keep\", \"method\": \"interp\"}" >"$TMP/tr.jsonl"
expect_rc 0 "transition as a batch line" -- "$MF" --json batch "$TMP/tr.jsonl"
cmp -s "$TMP/tr.bvh" "$TMP/tr-batch.bvh" && pass || fail "the batch line gives the command's output"
expect_rc 2 "transition --place elsewhere" -- "$MF" transition "$SAMPLE" "$SAMPLE" -o "$TMP/bad.bvh" --place here
expect_absent "$TMP/bad.bvh"
expect_rc 2 "transition --from-frame out of range" -- "$MF" transition "$SAMPLE" "$SAMPLE" -o "$TMP/bad.bvh" --from-frame 61 --method interp
expect_stderr "from_frame 61 is out of range" "transition names the bad frame"
expect_absent "$TMP/bad.bvh"
echo "{\"task\": \"transition\", \"in\": \"$SAMPLE\", \"to\": \"$SAMPLE\", \"out\": \"$TMP/bad.bvh\", \"place\": \"here\"}" >"$TMP/tr-bad.jsonl"
expect_rc 2 "transition with a bad batch key" -- "$MF" batch "$TMP/tr-bad.jsonl"
expect_stderr '"place" must be "auto" or "keep"' "batch transition names the bad key"
echo "{\"task\": \"transition\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/bad.bvh\"}" >"$TMP/tr-bad.jsonl"
expect_rc 2 "transition without clip B in a batch line" -- "$MF" batch "$TMP/tr-bad.jsonl"
expect_stderr 'missing key "to"' "batch transition needs \"to\""
expect_absent "$TMP/bad.bvh"

# ------------------------------------------------------------ resample
for method in interp zerovel; do
  expect_rc 0 "resample to 60 fps ($method)" -- "$MF" resample --in "$SAMPLE" --fps 60 --out "$TMP/r60-$method.bvh" --method "$method"
  expect_frames "$TMP/r60-$method.bvh" $(((N - 1) * 2 + 1))
  expect_frame_time "$TMP/r60-$method.bvh" 0.0166666667
  expect_rc 0 "resample to 60 fps keeps the input frames at even output frames" -- \
    "$DIFF" "$SAMPLE" "$TMP/r60-$method.bvh" --step 2
  [ -s "$TMP/err" ] && fail "resample to 60 fps printed to stderr" || pass
done
expect_rc 0 "resample to 15 fps" -- "$MF" resample --in "$SAMPLE" --fps 15 --out "$TMP/r15.bvh"
expect_frames "$TMP/r15.bvh" 31
expect_frame_time "$TMP/r15.bvh" 0.0666666667
expect_rc 0 "resample to 15 fps keeps even input frames" -- "$DIFF" "$TMP/r15.bvh" "$SAMPLE" --step 2
expect_rc 0 "resample to 24 fps" -- "$MF" resample --in "$SAMPLE" --fps 24 --out "$TMP/r24.bvh"
expect_frames "$TMP/r24.bvh" 49
expect_frame_time "$TMP/r24.bvh" 0.0416666667
# 60 * 23.3 / 30 + 1 = 47.6 frames: rounded down with a warning.
expect_rc 0 "resample to 23.3 fps" -- "$MF" resample --in "$SAMPLE" --fps 23.3 --out "$TMP/r23.bvh"
expect_frames "$TMP/r23.bvh" 47
expect_frame_time "$TMP/r23.bvh" 0.0429184549
expect_stderr "rounded down to 47 frames" "non-integer resample ratio warns"

# ------------------------------------------------------------ bad input: exit 2, nothing written
bad() {  # DESCRIPTION ARGS... (the output path is $TMP/bad.bvh)
  local what=$1
  shift
  expect_rc 2 "$what" -- "$MF" "$@"
  [ -s "$TMP/err" ] && pass || fail "$what: no message on stderr"
  expect_absent "$TMP/bad.bvh"
}
bad "keyframe out of range" inbetween --in "$SAMPLE" --keyframes 0,30,61 --out "$TMP/bad.bvh"
expect_stderr "keyframe 61 is out of range" "out-of-range message"
bad "negative keyframe" inbetween --in "$SAMPLE" --keyframes -1,30 --out "$TMP/bad.bvh"
bad "unsorted keyframes" inbetween --in "$SAMPLE" --keyframes 0,30,20 --out "$TMP/bad.bvh"
bad "duplicate keyframes" inbetween --in "$SAMPLE" --keyframes 0,30,30,60 --out "$TMP/bad.bvh"
bad "one keyframe" inbetween --in "$SAMPLE" --keyframes 30 --out "$TMP/bad.bvh"
bad "keyframes not numbers" inbetween --in "$SAMPLE" --keyframes 0,x --out "$TMP/bad.bvh"
bad "empty keyframe" inbetween --in "$SAMPLE" --keyframes 0,,60 --out "$TMP/bad.bvh"
bad "gap touching the start" fill --in "$SAMPLE" --gap 0:10 --out "$TMP/bad.bvh"
bad "gap touching the end" fill --in "$SAMPLE" --gap 10:61 --out "$TMP/bad.bvh"
bad "empty gap" fill --in "$SAMPLE" --gap 10:10 --out "$TMP/bad.bvh"
bad "reversed gap" fill --in "$SAMPLE" --gap 20:10 --out "$TMP/bad.bvh"
bad "malformed gap" fill --in "$SAMPLE" --gap 10-20 --out "$TMP/bad.bvh"
bad "fps zero" resample --in "$SAMPLE" --fps 0 --out "$TMP/bad.bvh"
bad "fps not a number" resample --in "$SAMPLE" --fps sixty --out "$TMP/bad.bvh"
bad "missing input file" inbetween --in "$TMP/does-not-exist.bvh" --keyframes 0,10 --out "$TMP/bad.bvh"
head -c 2000 "$SAMPLE" >"$TMP/truncated.bvh"
bad "truncated BVH" inbetween --in "$TMP/truncated.bvh" --keyframes 0,10 --out "$TMP/bad.bvh"
expect_stderr "truncated.bvh:" "BVH errors name the file"
printf 'HIERARCHY\nROOT a\n{\n OFFSET 0 0 zero\n}\n' >"$TMP/garbage.bvh"
bad "malformed BVH" fill --in "$TMP/garbage.bvh" --gap 1:2 --out "$TMP/bad.bvh"
bad "unknown flag" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh" --frobnicate 1
bad "unknown method" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh" --method magic
expect_stderr "unknown method 'magic'" "unknown method message"
bad "missing --keyframes" inbetween --in "$SAMPLE" --out "$TMP/bad.bvh"
bad "flag without value" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh" --method
bad "empty --method" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh" --method ""
bad "empty --model" --model "" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh" --method interp
bad "flag given twice" inbetween --in "$SAMPLE" --keyframes 0,10 --keyframes 0,20 --out "$TMP/bad.bvh"
bad "stray argument" fill --in "$SAMPLE" --gap 1:2 --out "$TMP/bad.bvh" extra
bad "output directory missing" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/no/such/dir/bad.bvh"
bad "unknown command" dance --in "$SAMPLE"
expect_stderr "unknown command 'dance'" "unknown command message"
bad "diff is a test tool, not a command" diff "$SAMPLE" "$SAMPLE"
bad "bad --threads" --threads 0 inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh"
bad "no command"

# ------------------------------------------------------------ the model (--model)
bad "--model that does not exist" --model "$TMP/none.mfm" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh"
expect_stderr "cannot open model file" "missing model message"
bad "--model that is not a model" --model "$SAMPLE" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh"
expect_stderr "not a motionfield model file" "not-a-model message"
bad "--model given twice" --model "$SAMPLE" --model "$SAMPLE" inbetween --in "$SAMPLE" --keyframes 0,10 --out "$TMP/bad.bvh"
expect_rc 0 "resample --help lists the methods" -- "$MF" resample --help
grep -q "^methods:" "$TMP/out" && grep -q "^    interp" "$TMP/out" && pass || fail "resample --help lists the methods"
# A method that needs the prior, with no model to load ($MF_MODEL names a missing file).
prior_method=$(awk '/^methods:/ { on = 1; next } on && /needs the model/ { print $1; exit }' "$TMP/out")
if [ -n "$prior_method" ]; then
  MF_MODEL="$TMP/none.mfm" bad "method $prior_method without a model" \
    resample --in "$SAMPLE" --fps 60 --out "$TMP/bad.bvh" --method "$prior_method"
fi
# Baselines need no model: a broken default model does not stop them.
MF_MODEL="$TMP/none.mfm" expect_rc 0 "baselines ignore the default model" -- \
  "$MF" inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/nomodel.bvh" --method interp

# ------------------------------------------------------------ renav
# A tiny random model on the 7-joint test skeleton (written by the C API tests'
# helper next to the CLI, or $MF_TEST_MODEL) and a reference clip on that
# skeleton: a 40-frame walk along +Z at 1.2 m/s.
expect_rc 0 "renav --help" -- "$MF" renav --help
grep -q "usage: motionfield renav" "$TMP/out" && pass || fail "renav --help prints its usage"
TINY=${MF_TEST_MODEL:-}
if [ -z "$TINY" ] && [ -x "$HELPER" ]; then
  "$HELPER" "$TMP/tiny.mfm" && TINY="$TMP/tiny.mfm"
fi
SMALL="$TMP/small.bvh"
awk 'BEGIN {
  print "HIERARCHY"; print "ROOT Hips"; print "{"; print " OFFSET 0 90 0"
  print " CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
  print " JOINT Spine"; print " {"; print "  OFFSET 0 20 0"; print "  CHANNELS 3 Zrotation Xrotation Yrotation"
  print "  JOINT Head"; print "  {"; print "   OFFSET 0 40 0"; print "   CHANNELS 3 Zrotation Xrotation Yrotation"
  print "   End Site"; print "   {"; print "    OFFSET 0 10 0"; print "   }"; print "  }"; print " }"
  split("L R", side, " ")
  for (k = 1; k <= 2; ++k) {
    x = (k == 1) ? 10 : -10
    print " JOINT UpperLeg_" side[k]; print " {"; print "  OFFSET " x " -5 0"; print "  CHANNELS 3 Zrotation Xrotation Yrotation"
    print "  JOINT Foot_" side[k]; print "  {"; print "   OFFSET 0 -80 0"; print "   CHANNELS 3 Zrotation Xrotation Yrotation"
    print "   End Site"; print "   {"; print "    OFFSET 0 -5 10"; print "   }"; print "  }"; print " }"
  }
  print "}"; print "MOTION"; print "Frames: 40"; print "Frame Time: 0.0333333"
  for (f = 0; f < 40; ++f) {
    a = 25 * sin(f * 0.35)
    printf "0 %.3f %.3f 0 0 %.3f  0 %.3f 0  0 0 0  0 %.3f 0  0 %.3f 0  0 %.3f 0  0 %.3f 0\n",
      90 + 2 * sin(f * 0.7), 4 * f, 5 * sin(f * 0.1), 3 * sin(f * 0.35), a, (a > 0 ? -a : 0), -a, (a < 0 ? a : 0)
  }
}' >"$SMALL"
printf 'x,z\n# a curve, 50 frames\n' >"$TMP/path50.csv"
awk 'BEGIN { for (f = 0; f < 50; ++f) printf "%.4f,%.4f\n", 0.5 * sin(f * 0.06), 0.04 * f }' >>"$TMP/path50.csv"
printf '0,0\n1,0\n1,1\n' >"$TMP/poly.csv"
printf 'x,z\n0,0\n' >"$TMP/one-point.csv"
printf '0,0\n0.1,nan\n0.2,0.2\n' >"$TMP/nan.csv"
printf '0,0\n0.1;0.1\n' >"$TMP/malformed.csv"
printf '1,1\n1,1\n1,1\n' >"$TMP/still.csv"
if [ -n "$TINY" ]; then
  expect_rc 0 "renav along a 50-frame path" -- "$MF" --model "$TINY" --threads 1 renav --in "$SMALL" --path "$TMP/path50.csv" --out "$TMP/renav.bvh"
  expect_frames "$TMP/renav.bvh" 50
  expect_frame_time "$TMP/renav.bvh" 0.0333333
  expect_rc 0 "renav --polyline --frames --method nemf-adam --fps 60" -- "$MF" --model "$TINY" --threads 1 renav --in "$SMALL" \
    --polyline "$TMP/poly.csv" --frames 30 --fps 60 --method nemf-adam --out "$TMP/renav-poly.bvh"
  expect_frames "$TMP/renav-poly.bvh" 30
  expect_frame_time "$TMP/renav-poly.bvh" 0.0166666667
  bad "renav: a path with one point" --model "$TINY" renav --in "$SMALL" --path "$TMP/one-point.csv" --out "$TMP/bad.bvh"
  expect_stderr "at least two points" "one-point path message"
  bad "renav: a non-finite value" --model "$TINY" renav --in "$SMALL" --path "$TMP/nan.csv" --out "$TMP/bad.bvh"
  expect_stderr "nan.csv:2: non-finite" "non-finite path message names the line"
  bad "renav: a malformed CSV" --model "$TINY" renav --in "$SMALL" --path "$TMP/malformed.csv" --out "$TMP/bad.bvh"
  expect_stderr "malformed.csv:2:" "malformed path message names the line"
  bad "renav: a zero-length path" --model "$TINY" renav --in "$SMALL" --path "$TMP/still.csv" --out "$TMP/bad.bvh"
  bad "renav: a missing path file" --model "$TINY" renav --in "$SMALL" --path "$TMP/none.csv" --out "$TMP/bad.bvh"
  bad "renav: a skeleton that does not match the model" --model "$TINY" renav --in "$SAMPLE" --path "$TMP/path50.csv" --out "$TMP/bad.bvh"
  expect_stderr "joints" "skeleton mismatch message"
  bad "renav: unknown method" --model "$TINY" renav --in "$SMALL" --path "$TMP/path50.csv" --out "$TMP/bad.bvh" --method magic
  expect_stderr "unknown re-navigation method 'magic'" "renav unknown method message"
  bad "renav: --frames with --path" --model "$TINY" renav --in "$SMALL" --path "$TMP/path50.csv" --frames 10 --out "$TMP/bad.bvh"
  bad "renav: --path and --polyline" --model "$TINY" renav --in "$SMALL" --path "$TMP/path50.csv" --polyline "$TMP/poly.csv" --out "$TMP/bad.bvh"
  bad "renav: --fps 0" --model "$TINY" renav --in "$SMALL" --path "$TMP/path50.csv" --fps 0 --out "$TMP/bad.bvh"
  # The same jobs in batch mode give the same files; a bad renav line fails alone.
  {
    echo "{\"task\": \"renav\", \"in\": \"$SMALL\", \"out\": \"$TMP/b-renav.bvh\", \"path\": \"$TMP/path50.csv\"}"
    echo "{\"task\": \"renav\", \"in\": \"$SMALL\", \"out\": \"$TMP/b-renav-poly.bvh\", \"polyline\": \"$TMP/poly.csv\", \"frames\": 30, \"fps\": 60, \"method\": \"nemf-adam\"}"
    echo "{\"task\": \"renav\", \"in\": \"$SMALL\", \"out\": \"$TMP/b-bad.bvh\", \"path\": \"$TMP/one-point.csv\"}"
  } >"$TMP/renav.jsonl"
  expect_rc 2 "batch renav with one bad line" -- "$MF" --model "$TINY" --threads 1 batch "$TMP/renav.jsonl"
  expect_stderr "at least two points" "batch renav names the bad line's problem"
  expect_rc 0 "batch renav = renav" -- "$DIFF" "$TMP/b-renav.bvh" "$TMP/renav.bvh" --tol 1e-9
  expect_rc 0 "batch renav --polyline = renav --polyline" -- "$DIFF" "$TMP/b-renav-poly.bvh" "$TMP/renav-poly.bvh" --tol 1e-9
  expect_absent "$TMP/b-bad.bvh"
  # --jobs 2: the same files bit for bit and the same messages and --json lines, in line order.
  "$MF" --model "$TINY" --threads 1 --json batch --jobs 1 "$TMP/renav.jsonl" >"$TMP/serial.json" 2>"$TMP/serial.err"
  sed "s|b-renav|p-renav|g" "$TMP/renav.jsonl" >"$TMP/renav-par.jsonl"
  expect_rc 2 "batch --jobs 2 with one bad line" -- "$MF" --model "$TINY" --threads 1 --json batch --jobs 2 "$TMP/renav-par.jsonl"
  cmp -s "$TMP/p-renav.bvh" "$TMP/b-renav.bvh" && pass || fail "batch --jobs 2 output differs from the serial run's"
  cmp -s "$TMP/p-renav-poly.bvh" "$TMP/b-renav-poly.bvh" && pass || fail "batch --jobs 2 output (polyline) differs"
  sed "s|p-renav|b-renav|g; s|renav-par.jsonl|renav.jsonl|g" "$TMP/out" >"$TMP/par.json"
  awk '{ gsub(/"timings_ms":\{[^}]*\}/, ""); print }' "$TMP/par.json" >"$TMP/par.cut"
  awk '{ gsub(/"timings_ms":\{[^}]*\}/, ""); print }' "$TMP/serial.json" >"$TMP/serial.cut"
  cmp -s "$TMP/par.cut" "$TMP/serial.cut" && pass || fail "batch --jobs 2 --json lines differ from the serial run's"
  sed "s|renav-par.jsonl|renav.jsonl|g" "$TMP/err" | cmp -s - "$TMP/serial.err" && pass ||
    fail "batch --jobs 2 messages differ from the serial run's"
  bad "batch --jobs 0" batch --jobs 0 "$TMP/renav.jsonl"
  # Without --jobs: the cores divided by --threads, 1 to 8.
  cores=$(nproc)
  for t in 1 2; do
    want=$((cores / t)); [ "$want" -lt 1 ] && want=1; [ "$want" -gt 8 ] && want=8
    "$MF" --model "$TINY" --threads $t --verbose batch "$TMP/renav-par.jsonl" >/dev/null 2>"$TMP/err"
    grep -q "batch: $want jobs\? at once" "$TMP/err" && pass || fail "batch --threads $t runs $want jobs at once by default"
  done
  # Without --threads: one intra-op thread per batch job, and a job per core;
  # a single command takes 1 thread too (Settings::threads: why).
  want=$cores; [ "$want" -gt 8 ] && want=8
  "$MF" --model "$TINY" --verbose batch "$TMP/renav-par.jsonl" >/dev/null 2>"$TMP/err"
  grep -q "motionfield: 1 intra-op threads" "$TMP/err" && grep -q "batch: $want jobs\? at once" "$TMP/err" && pass ||
    fail "batch without --threads runs $want jobs of 1 thread at once"
  want=1
  "$MF" --model "$TINY" --verbose renav --in "$SMALL" --path "$TMP/path50.csv" --out "$TMP/renav-default.bvh" >/dev/null 2>"$TMP/err"
  grep -q "motionfield: $want intra-op threads" "$TMP/err" && pass || fail "a single command without --threads runs on $want threads"
else
  fail "no tiny model (mf_capi_tiny_model not built, MF_TEST_MODEL unset): the renav runs could not run"
fi
bad "renav without a path" renav --in "$SMALL" --out "$TMP/bad.bvh"
MF_MODEL="$TMP/none.mfm" bad "renav without a model" renav --in "$SMALL" --path "$TMP/path50.csv" --out "$TMP/bad.bvh"

# ------------------------------------------------------------ transformer methods
# Tiny random transformers next to a tiny prior (mf_capi_tiny_model --transformers),
# so no trained file is needed; a missing helper is a failure (CTest builds it).
if [ -x "$HELPER" ] && mkdir -p "$TMP/tr" "$TMP/notr" && "$HELPER" "$TMP/tr/prior.mfm" --transformers &&
   "$HELPER" "$TMP/notr/prior.mfm"; then
  for method in context detail citl nemf-citl; do
    expect_rc 0 "inbetween --method $method (transformers next to the model)" -- \
      "$MF" --model "$TMP/tr/prior.mfm" --threads 1 inbetween --in "$SMALL" --keyframes 0,12,39 \
      --out "$TMP/tr-$method.bvh" --method "$method"
    expect_frames "$TMP/tr-$method.bvh" 40
    expect_rc 0 "$method keeps the keyframes" -- "$DIFF" "$SMALL" "$TMP/tr-$method.bvh" --frames 0,12,39
  done
  expect_rc 0 "fill --method detail" -- "$MF" --model "$TMP/tr/prior.mfm" --threads 1 fill --in "$SMALL" --gap 10:25 \
    --out "$TMP/tr-fill.bvh" --method detail
  expect_rc 0 "fill --method detail keeps the known frames" -- "$DIFF" "$SMALL" "$TMP/tr-fill.bvh" --frames 0,9,25,39
  printf '%s\n' "{\"task\": \"inbetween\", \"in\": \"$SMALL\", \"out\": \"$TMP/tr-b1.bvh\", \"keyframes\": [0, 20, 39], \"method\": \"citl\"}" \
    "{\"task\": \"fill\", \"in\": \"$SMALL\", \"out\": \"$TMP/tr-b2.bvh\", \"gap\": [5, 30], \"method\": \"context\"}" >"$TMP/tr-jobs.jsonl"
  expect_rc 0 "batch with transformer methods" -- "$MF" --model "$TMP/tr/prior.mfm" --threads 1 batch "$TMP/tr-jobs.jsonl"
  expect_frames "$TMP/tr-b1.bvh" 40
  expect_frames "$TMP/tr-b2.bvh" 40
  bad "citl without its file" --model "$TMP/notr/prior.mfm" inbetween --in "$SMALL" --keyframes 0,39 \
    --out "$TMP/bad.bvh" --method citl
  expect_stderr "needs models/motionfield-citl.mfm" "missing transformer message"
  expect_rc 0 "--citl PATH adds the transformer" -- "$MF" --model "$TMP/notr/prior.mfm" --citl "$TMP/tr/motionfield-citl.mfm" \
    --threads 1 inbetween --in "$SMALL" --keyframes 0,20,39 --out "$TMP/tr-explicit.bvh" --method citl
  bad "--twostage naming a prior" --model "$TMP/notr/prior.mfm" --twostage "$TMP/notr/prior.mfm" inbetween --in "$SMALL" \
    --keyframes 0,39 --out "$TMP/bad.bvh" --method detail
  expect_stderr "wrong kind" "--twostage with a file of another kind"
  bad "keys further apart than the transformer's window" --model "$TMP/tr/prior.mfm" inbetween --in "$SMALL" \
    --keyframes 0,39 --out "$TMP/bad.bvh" --method citl
  expect_stderr "frames apart" "long-gap message"
else
  fail "mf_capi_tiny_model not built or failed: the transformer method runs could not run"
fi

# ------------------------------------------------------------ the command line (issue 17)
expect_rc 0 "--version" -- "$MF" --version
grep -q "^library [0-9.]*, ABI [0-9]" "$TMP/out" && pass || fail "--version prints the library and ABI versions"
if [ -n "$TINY" ]; then
  expect_rc 0 "--version with a model" -- "$MF" --model "$TINY" --version
  grep -q "^model .*: format [0-9]*, 7 joints" "$TMP/out" && pass || fail "--version prints the model's format"
fi
expect_rc 0 "-i/-o and --length-scale" -- "$MF" --length-scale 0.01 inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/io.bvh" --method interp
expect_rc 0 "-i/-o output = --in/--out output" -- "$DIFF" "$TMP/io.bvh" "$TMP/kf-interp.bvh" --frames 0,60
"$MF" inbetween --in - --keyframes "$KEYS" --out - --method interp <"$SAMPLE" >"$TMP/piped.bvh" 2>"$TMP/err"
[ $? -eq 0 ] && pass || fail "--in - --out - (stdin to stdout)"
expect_rc 0 "stdin to stdout = files" -- "$DIFF" "$TMP/piped.bvh" "$TMP/kf-interp.bvh" --tol 1e-9
expect_absent "$(pwd)/-"
cat "$SAMPLE" | "$MF" resample -i - --fps 60 -o "$TMP/piped60.bvh" --method interp 2>"$TMP/err"
[ $? -eq 0 ] && pass || fail "--in - from a pipe"
expect_frames "$TMP/piped60.bvh" $(((N - 1) * 2 + 1))
expect_rc 0 "--json" -- "$MF" --json inbetween --in "$SAMPLE" --keyframes "$KEYS" --out "$TMP/json.bvh" --method interp
[ "$(wc -l <"$TMP/out")" -eq 1 ] && pass || fail "--json prints one line"
grep -q '^{"task":"inbetween","in":".*","out":".*json.bvh","status":"ok","method":"interp","model":"","frames_in":61,"frames_out":61,"timings_ms":{"read":.*,"warnings":\[\]}$' "$TMP/out" &&
  pass || { fail "--json summary"; cat "$TMP/out"; }
expect_rc 0 "--json passes warnings on" -- "$MF" --json resample --in "$SAMPLE" --fps 23.3 --out "$TMP/json23.bvh"
grep -q '"warnings":\[".*rounded down to 47 frames' "$TMP/out" && pass || fail "--json lists the warnings"
expect_rc 2 "--json reports a failure" -- "$MF" --json fill --in "$SAMPLE" --gap 0:10 --out "$TMP/bad.bvh"
grep -q '"status":"error","exit_code":2,"error":".*first frame' "$TMP/out" && pass || fail "--json error object"
bad "--json with --out -" --json inbetween --in "$SAMPLE" --keyframes 0,60 --out - --method interp
expect_rc 0 "--quiet" -- "$MF" --quiet resample --in "$SAMPLE" --fps 23.3 --out "$TMP/quiet.bvh"
[ -s "$TMP/err" ] && fail "--quiet still printed a warning" || pass
if [ -n "$TINY" ]; then
  # A terminal on stderr (script(1) gives one): the progress bar shows iterations.
  # The bar redraws at most every 100 ms, so the job must outlast that: Adam's
  # 600 iterations on the bundled prior do (about 1 s; on the tiny model the
  # Eigen runtime finishes them in under 100 ms).
  script -qec "\"$MF\" --model \"$SRC/models/motionfield-prior.mfm\" --threads 1 inbetween --in \"$SAMPLE\" --keyframes 0,60 --out \"$TMP/tty.bvh\" --method nemf-adam" \
    /dev/null >"$TMP/tty.out" 2>&1
  grep -q "iterations" "$TMP/tty.out" && pass || fail "progress bar on a terminal"
  script -qec "\"$MF\" --quiet --model \"$TINY\" --threads 1 inbetween --in \"$SMALL\" --keyframes 0,39 --out \"$TMP/tty.bvh\" --method nemf" \
    /dev/null >"$TMP/tty.out" 2>&1
  grep -q "iterations" "$TMP/tty.out" && fail "--quiet drew the progress bar" || pass
  expect_rc 0 "no progress bar when stderr is not a terminal" -- "$MF" --model "$TINY" --threads 1 inbetween --in "$SMALL" \
    --keyframes 0,39 --out "$TMP/notty.bvh" --method nemf
  # (A tiny random prior cannot reach the keys: the fallback's warning may be there, nothing else.)
  grep -v "^motionfield: warning: interpolation was used" "$TMP/err" | grep -q . && fail "progress printed to a non-terminal stderr" || pass
  # --no-fallback keeps the solver's result where the fallback interpolates (and says so).
  expect_rc 0 "fill with the fallback" -- "$MF" --model "$TINY" --threads 1 fill --in "$SMALL" --gap 5:35 \
    --out "$TMP/fb.bvh" --method nemf
  if grep -q "interpolation was used" "$TMP/err"; then
    expect_rc 0 "fill --no-fallback" -- "$MF" --model "$TINY" --threads 1 fill --in "$SMALL" --gap 5:35 \
      --out "$TMP/nofb.bvh" --method nemf --no-fallback
    grep -q "interpolation was used" "$TMP/err" && fail "--no-fallback still fell back" || pass
    cmp -s "$TMP/fb.bvh" "$TMP/nofb.bvh" && fail "--no-fallback gave the interpolated result" || pass
  fi
fi

# ------------------------------------------------------------ bad input and faults (issue 18, docs/RELIABILITY.md)
# 1: devices are written in place, never replaced; a full one fails with the reason (7).
expect_rc 0 "--out /dev/null" -- "$MF" inbetween --in "$SAMPLE" --keyframes 0,60 --out /dev/null --method interp
[ -c /dev/null ] && pass || fail "/dev/null is no longer a character device"
if [ -c /dev/full ]; then
  expect_rc 2 "--out /dev/full" -- "$MF" inbetween --in "$SAMPLE" --keyframes 0,60 --out /dev/full --method interp
  expect_stderr "cannot write /dev/full: No space left on device" "full device message"
  [ -c /dev/full ] && pass || fail "/dev/full is no longer a character device"
  "$MF" inbetween --in "$SAMPLE" --keyframes 0,60 --out - --method interp >/dev/full 2>"$TMP/err"
  [ $? -eq 2 ] && pass || fail "--out - onto a full disk: exit code 2"
  expect_stderr "cannot write the standard output: No space left on device" "full stdout message"
fi
# 2: endless inputs are refused before reading.
expect_rc 2 "--in /dev/zero" -- timeout 20 "$MF" inbetween --in /dev/zero --keyframes 0,1 --out "$TMP/bad.bvh"
expect_stderr "cannot read BVH file /dev/zero: it is a device, not a file" "/dev/zero message"
expect_rc 2 "--in /dev/urandom" -- timeout 20 "$MF" inbetween --in /dev/urandom --keyframes 0,1 --out "$TMP/bad.bvh"
expect_rc 2 "batch /dev/zero" -- timeout 20 "$MF" batch /dev/zero
expect_stderr "cannot read the batch file /dev/zero: it is a device, not a file" "batch /dev/zero message"
# 3: bytes of the input are escaped in messages.
printf 'HIERARCHY\nROOT a\033[2J\033]0;owned\007\n{\n OFFSET 0 0 zero\033[31m\n}\n' >"$TMP/escape.bvh"
bad "a BVH token with escape sequences" inbetween --in "$TMP/escape.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
LC_ALL=C grep -q "$(printf '\033')" "$TMP/err" && fail "an escape byte reached stderr" || pass
expect_stderr 'x1b' "escape bytes are shown escaped"
mkdir -p "$TMP/faults"
cp "$SAMPLE" "$TMP/faults/walk.bvh"
printf '%s\n' '{"task": "inbetween", "in": "a\u001b[31mred.bvh", "out": "x.bvh", "keyframes": [0, 1]}' \
  '{"task": "inbetween", "in": "walk.bvh\u0000.evil", "out": "y.bvh", "keyframes": [0, 60]}' >"$TMP/faults/esc.jsonl"
in_dir "$TMP/faults" expect_rc 2 "batch: escape sequences and a NUL in paths" -- "$MF" batch esc.jsonl
LC_ALL=C grep -q "$(printf '\033')" "$TMP/err" && fail "an escape byte of a batch path reached stderr" || pass
expect_stderr 'a\\x1b\[31mred.bvh' "batch path shown escaped"
# 4: a NUL in a batch path is refused, not cut.
expect_stderr 'line 2: error: "in" contains a NUL character' "NUL in a batch path"
expect_absent "$TMP/faults/y.bvh"
# 5: messages are bounded.
LONG="$TMP/$(head -c 100000 /dev/zero | tr '\0' p).bvh"
bad "a 100 kB path" inbetween --in "$LONG" --keyframes 0,1 --out "$TMP/bad.bvh"
[ "$(wc -c <"$TMP/err")" -le 5000 ] && pass || fail "the message of a 100 kB path has $(wc -c <"$TMP/err") bytes"
expect_stderr "bytes left out" "long message elided"
# 8: the output may not be the input (by inode), in batch mode neither, nor two jobs one output.
cp "$SAMPLE" "$TMP/faults/same.bvh"
in_dir "$TMP/faults" expect_rc 2 "--out = --in" -- "$MF" inbetween --in same.bvh --keyframes 0,60 --out ./same.bvh --method interp
expect_stderr "the output ./same.bvh is the input same.bvh" "--out = --in message"
cmp -s "$SAMPLE" "$TMP/faults/same.bvh" && pass || fail "--out = --in replaced the input"
printf '%s\n' '{"task": "inbetween", "in": "same.bvh", "out": "same.bvh", "keyframes": [0, 60], "method": "interp"}' \
  '{"task": "inbetween", "in": "walk.bvh", "out": "one.bvh", "keyframes": [0, 60], "method": "interp"}' \
  '{"task": "inbetween", "in": "walk.bvh", "out": "./one.bvh", "keyframes": [0, 30, 60], "method": "interp"}' \
  '{"task": "inbetween", "in": "walk.bvh", "out": "-", "keyframes": [0, 60], "method": "interp"}' >"$TMP/faults/same.jsonl"
in_dir "$TMP/faults" expect_rc 2 "batch: out = in, two jobs one output" -- "$MF" --json batch same.jsonl
expect_stderr "line 1: error: the output same.bvh is the input same.bvh" "batch out = in"
expect_stderr "line 3: error: line 2 already writes ./one.bvh" "batch duplicate output"
expect_stderr "line 4: error: .*for single commands" "batch refuses -"
cmp -s "$SAMPLE" "$TMP/faults/same.bvh" && pass || fail "batch out = in replaced the input"
expect_frames "$TMP/faults/one.bvh" "$N"
[ "$(grep -c '"status"' "$TMP/out")" -eq 4 ] && pass || fail "batch --json prints one object per job"
# 6: a transformer file that does not load is named when the default method runs without it.
if [ -x "$HELPER" ] && mkdir -p "$TMP/trunc" && "$HELPER" "$TMP/trunc/motionfield-prior.mfm" --transformers; then
  head -c 200 "$TMP/trunc/motionfield-twostage.mfm" >"$TMP/trunc/t" && mv "$TMP/trunc/t" "$TMP/trunc/motionfield-twostage.mfm"
  expect_rc 0 "a truncated two-stage file with the default method" -- \
    "$MF" --model "$TMP/trunc/motionfield-prior.mfm" --threads 1 inbetween --in "$SMALL" --keyframes 0,20,39 --out "$TMP/trunc.bvh"
  expect_stderr "warning: motionfield-twostage.mfm next to the model did not load" "truncated transformer warning"
  expect_rc 0 "--version names it too" -- "$MF" --model "$TMP/trunc/motionfield-prior.mfm" --version
  expect_stderr "motionfield-twostage.mfm next to the model did not load" "--version warns about the truncated file"
else
  fail "mf_capi_tiny_model not built or failed: the truncated transformer case could not run"
fi

# ------------------------------------------------------------ other rigs
# The sample on Mixamo's joint names and in metres (offsets and root positions
# scaled), with the bundled model: detected unit, the map, a task on that rig
# written back in its names and unit, and rig map errors naming the file.
if [ -f "$SRC/models/motionfield-prior.mfm" ]; then
  MIX="$TMP/mixamo-m.bvh"
  sed -e 's/JOINT Chest$/JOINT mixamorig:Spine2/' -e 's/JOINT \(Hips\|Spine\|Neck\|Head\)$/JOINT mixamorig:\1/' \
    -e 's/JOINT UpperArm_\([LR]\)$/JOINT mixamorig:\1Arm/' -e 's/JOINT LowerArm_\([LR]\)$/JOINT mixamorig:\1ForeArm/' \
    -e 's/JOINT Shoulder_\([LR]\)$/JOINT mixamorig:\1Shoulder/' -e 's/JOINT Hand_\([LR]\)$/JOINT mixamorig:\1Hand/' \
    -e 's/JOINT UpperLeg_\([LR]\)$/JOINT mixamorig:\1UpLeg/' -e 's/JOINT LowerLeg_\([LR]\)$/JOINT mixamorig:\1Leg/' \
    -e 's/JOINT Foot_\([LR]\)$/JOINT mixamorig:\1Foot/' -e 's/JOINT Toes_\([LR]\)$/JOINT mixamorig:\1ToeBase/' \
    -e 's/mixamorig:L\([A-Z]\)/mixamorig:Left\1/' -e 's/mixamorig:R\([A-Z]\)/mixamorig:Right\1/' "$SAMPLE" |
    awk 'motion && NF > 6 { for (i = 1; i <= 9; i++) if (i <= 3 || i >= 7) $i = $i * 0.01 }
         $1 == "OFFSET" { $2 *= 0.01; $3 *= 0.01; $4 *= 0.01 }
         /^Frame Time:/ { motion = 1 } { print }' >"$MIX"
  grep -q "JOINT mixamorig:LeftForeArm" "$MIX" && pass || fail "the Mixamo-named sample has mixamorig:LeftForeArm"
  rig_method=nemf
  if [ -f "$SRC/models/motionfield-twostage.mfm" ]; then rig_method=detail; fi

  expect_rc 0 "rig prints the unit and the map" -- "$MF" rig "$MIX"
  grep -q "unit m (detected" "$TMP/out" && pass || fail "rig detects metres"
  grep -Eq "mixamorig:LeftForeArm +-> LowerArm_L +name" "$TMP/out" && pass || fail "rig prints the map"
  grep -q "user joints left out: none" "$TMP/out" && pass || fail "rig prints the joints left out"
  expect_rc 0 "rig --json" -- "$MF" rig "$MIX" --json
  grep -q '^{"unit":"m","length_scale":1' "$TMP/out" && pass || fail "rig --json prints the description"
  expect_rc 0 "rig --units cm" -- "$MF" --units cm rig "$MIX"
  grep -q "unit cm (given" "$TMP/out" && pass || fail "rig says a given unit"

  expect_rc 0 "inbetween on another rig ($rig_method)" -- \
    "$MF" --threads 1 inbetween --in "$MIX" --keyframes 0,20,40,60 --out "$TMP/mix-kf.bvh" --method "$rig_method"
  expect_frames "$TMP/mix-kf.bvh" "$N"
  grep -q "JOINT mixamorig:LeftForeArm" "$TMP/mix-kf.bvh" && pass || fail "the output has the user's joint names"
  grep -q "OFFSET 0.14 0 0" "$TMP/mix-kf.bvh" && pass || fail "the output is in the input's unit (metres)"
  expect_rc 0 "known frames kept on another rig" -- "$DIFF" "$MIX" "$TMP/mix-kf.bvh" --frames 0,20,40,60
  expect_rc 3 "...and the others solved" -- "$DIFF" "$MIX" "$TMP/mix-kf.bvh" --frames 10

  printf '{"mixamorig:Spine2": "Chest"}\n' >"$TMP/map.json"
  printf '{"mixamorig:Hips": "NoSuchJoint"}\n' >"$TMP/badmap.json"
  expect_rc 0 "fill with --rig-map" -- "$MF" --threads 1 fill --in "$MIX" --gap 10:30 --out "$TMP/mix-fill.bvh" \
    --method "$rig_method" --rig-map "$TMP/map.json"
  expect_rc 0 "rig --rig-map" -- "$MF" rig "$MIX" --rig-map "$TMP/map.json"
  grep -Eq "mixamorig:Spine2 +-> Chest +map file" "$TMP/out" && pass || fail "rig says which joints the map file gave"
  bad "a rig map naming a missing joint" --rig-map "$TMP/badmap.json" inbetween --in "$MIX" --keyframes 0,60 \
    --out "$TMP/bad.bvh" --method "$rig_method"
  expect_stderr "badmap.json: rig map: the model has no joint named 'NoSuchJoint'" "rig map errors name the file"
  expect_rc 2 "rig with a bad map" -- "$MF" rig "$MIX" --rig-map "$TMP/badmap.json"
  expect_stderr "badmap.json: rig map:" "rig names the bad map file"
  bad "a missing rig map file" inbetween --in "$MIX" --keyframes 0,60 --out "$TMP/bad.bvh" --rig-map "$TMP/none.json"
  expect_stderr "cannot open rig map file .*none.json: No such file or directory" "missing map file message"
  bad "an unknown unit" --units furlong inbetween --in "$MIX" --keyframes 0,60 --out "$TMP/bad.bvh"
  expect_stderr "unknown length unit 'furlong'" "unknown unit message"

  printf '%s\n' "{\"task\": \"fill\", \"in\": \"$MIX\", \"out\": \"$TMP/mix-b1.bvh\", \"gap\": [10, 30], \"method\": \"$rig_method\", \"rig_map\": \"$TMP/map.json\", \"units\": \"m\"}" \
    "{\"task\": \"fill\", \"in\": \"$MIX\", \"out\": \"$TMP/mix-b2.bvh\", \"gap\": [10, 30], \"method\": \"$rig_method\", \"rig_map\": \"$TMP/badmap.json\"}" \
    "{\"task\": \"inbetween\", \"in\": \"$MIX\", \"out\": \"$TMP/mix-b3.bvh\", \"keyframes\": [0, 60], \"method\": \"interp\", \"units\": 1}" \
    >"$TMP/rig-jobs.jsonl"
  expect_rc 2 "batch with rig_map and units" -- "$MF" --threads 1 batch "$TMP/rig-jobs.jsonl"
  expect_frames "$TMP/mix-b1.bvh" "$N"
  expect_frames "$TMP/mix-b3.bvh" "$N"
  expect_absent "$TMP/mix-b2.bvh"
  expect_stderr "line 2: error: .*badmap.json: rig map" "batch names the job's bad map file"
else
  fail "no bundled model (models/motionfield-prior.mfm is in the repository): the other-rig runs could not run"
fi

# ------------------------------------------------------------ batch
mkdir -p "$TMP/batch"
cp "$SAMPLE" "$TMP/batch/walk.bvh"
cat >"$TMP/batch/jobs.jsonl" <<'EOF'
{"id": "kf", "task": "inbetween", "in": "walk.bvh", "out": "b1.bvh", "keyframes": [0, 20, 40, 60], "frames": 61, "fps_in": 30}

{"id": "bad-gap", "task": "fill", "in": "walk.bvh", "out": "b2.bvh", "gap": [0, 10]}
{"task": "resample", "in": "walk.bvh", "out": "b3.bvh", "fps": 60, "method": "zerovel", "note": {"any": ["thing"]}}
{"task": "fill", "in": "walk.bvh", "out": "b4.bvh", "gap": [5, 8], "keyframes": [0, 30, 60]}
EOF
in_dir "$TMP/batch" expect_rc 2 "batch with one bad job" -- "$MF" batch jobs.jsonl
expect_frames "$TMP/batch/b1.bvh" 61
expect_frames "$TMP/batch/b3.bvh" 121
expect_frames "$TMP/batch/b4.bvh" 61
expect_absent "$TMP/batch/b2.bvh"
expect_stderr "line 3" "batch names the failed job's line"
expect_stderr "bad-gap" "batch names the failed job's id"
expect_stderr "touches the first frame" "batch gives the reason"
if grep -q "line [145]" "$TMP/err"; then fail "batch reported a good job"; else pass; fi
in_dir "$TMP/batch" expect_rc 0 "fill keyframes are authoritative" -- "$DIFF" walk.bvh b4.bvh --frames 0,30,60
in_dir "$TMP/batch" expect_rc 3 "fill keyframes are authoritative (frames 1..29 filled)" -- "$DIFF" walk.bvh b4.bvh --frames 15
in_dir "$TMP/batch" expect_rc 0 "batch job keeps its keyframes" -- "$DIFF" walk.bvh b1.bvh --frames 0,20,40,60

printf '%s\n' '{"task": "inbetween", "in": "walk.bvh", "out": "g1.bvh", "keyframes": [0, 60]}' \
  '{"task": "resample", "in": "walk.bvh", "out": "g2.bvh", "fps": 23.3}' >"$TMP/batch/good.jsonl"
in_dir "$TMP/batch" expect_rc 0 "batch, all good" -- "$MF" batch good.jsonl
expect_frames "$TMP/batch/g1.bvh" 61
expect_frames "$TMP/batch/g2.bvh" 47
expect_stderr "line 2: warning: .*rounded down" "batch passes warnings on with the line"

printf '%s\n' '{"task": "inbetween", "in": "walk.bvh", "out": "x.bvh", "keyframes": [0, 60],}' \
  '["not", "an", "object"]' '{"task": "inbetween", "in": "missing.bvh", "out": "y.bvh", "keyframes": [0, 1]}' \
  >"$TMP/batch/allbad.jsonl"
in_dir "$TMP/batch" expect_rc 2 "batch, all bad" -- "$MF" batch allbad.jsonl
expect_stderr "line 1: error: invalid JSON: column" "batch names the JSON error's column"
expect_stderr "line 2: error:" "batch rejects non-objects"
expect_stderr "line 3: error:" "batch reports a missing input"
expect_rc 2 "batch file missing" -- "$MF" batch "$TMP/batch/none.jsonl"

# ------------------------------------------------------------ constraints (issue 16, docs/CONSTRAINTS.md)
cat >"$TMP/c.json" <<'JSON'
{"keys": [{"frame": 30, "joints": ["UpperArm_L", "LowerArm_L"]}, {"frame": 45, "root": "position"}],
 "targets": [{"frame": 20, "joint": "Hand_R", "position": [20, 110, 30]}],
 "contacts": [{"joint": "Foot_L", "first": 50, "last": 55}]}
JSON
expect_rc 0 "inbetween --constraints (interp)" -- "$MF" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/c.bvh" \
  --constraints "$TMP/c.json" --method interp --report "$TMP/c-report.json"
expect_rc 0 "constraints keep the whole-pose keys" -- "$DIFF" "$SAMPLE" "$TMP/c.bvh" --frames 0,60
grep -q '"targets"' "$TMP/c-report.json" && pass || fail "--report writes the constraint report"
grep -q '"rotations": 44' "$TMP/c-report.json" && pass || fail "the report counts the whole and partial key rotations"
expect_rc 0 "fill --constraints" -- "$MF" fill -i "$SAMPLE" --gap 10:40 -o "$TMP/cf.bvh" --method interp \
  --constraints "$TMP/c.json" --json
grep -q '"constraints":{' "$TMP/out" && pass || fail "--json carries the constraint report"
expect_rc 0 "inbetween --alternatives 1 (nemf)" -- "$MF" --threads 1 inbetween -i "$SAMPLE" --keyframes 0,60 \
  -o "$TMP/alt.bvh" --alternatives 1 --method nemf
expect_frames "$TMP/alt_1.bvh" "$N"
expect_rc 0 "an alternative keeps the keys" -- "$DIFF" "$SAMPLE" "$TMP/alt_1.bvh" --frames 0,60
cmp -s "$TMP/alt.bvh" "$TMP/alt_1.bvh" && fail "the alternative equals the default solution" || pass
printf '%s\n' "{\"task\": \"inbetween\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/bc.bvh\", \"keyframes\": [0, 60], \"method\": \"interp\", \"constraints\": $(tr -d '\n' <"$TMP/c.json"), \"report\": \"$TMP/bc-report.json\"}" \
  "{\"task\": \"inbetween\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/bc2.bvh\", \"keyframes\": [0, 60], \"method\": \"interp\", \"constraints\": \"$TMP/c.json\"}" \
  "{\"task\": \"inbetween\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/bc3.bvh\", \"keyframes\": [0, 60], \"constraints\": 3}" \
  >"$TMP/cjobs.jsonl"
expect_rc 2 "batch with constraints (one bad line)" -- "$MF" batch "$TMP/cjobs.jsonl"
expect_stderr 'line 3: error: "constraints" must be a file name or an object' "batch names a bad constraints value"
cmp -s "$TMP/bc.bvh" "$TMP/c.bvh" && pass || fail "batch inline constraints = --constraints"
cmp -s "$TMP/bc2.bvh" "$TMP/c.bvh" && pass || fail "batch constraints file = --constraints"
cmp -s "$TMP/bc-report.json" "$TMP/c-report.json" && pass || fail "batch report = --report"
echo '{"keys": [{"frame": 30, "joints": ["Tail"]}]}' >"$TMP/c-bad.json"
bad "constraints: unknown joint" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --constraints "$TMP/c-bad.json" --method interp
expect_stderr "unknown joint 'Tail'" "unknown joint message"
echo '{"contacts": [{"joint": "Foot_L", "first": 5, "last": 20}, {"joint": "Foot_L", "first": 10, "last": 30}]}' >"$TMP/c-bad.json"
bad "constraints: overlapping contacts" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --constraints "$TMP/c-bad.json" --method interp
expect_stderr "overlaps contact 5..20" "overlapping contacts message"
echo '{"targets": [{"frame": 99, "joint": "Hand_R", "position": [0, 0, 0]}]}' >"$TMP/c-bad.json"
bad "constraints: frame out of range" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --constraints "$TMP/c-bad.json" --method interp
echo '{"keys": [{"frame": 3, "joints": "Head"}]}' >"$TMP/c-bad.json"
bad "constraints: joints not an array" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --constraints "$TMP/c-bad.json" --method interp
bad "constraints file missing" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --constraints "$TMP/none.json"
bad "constraints with a method that takes whole poses only" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --constraints "$TMP/c.json" --method zerovel
expect_stderr "takes whole-pose keys only" "whole-pose-only method message"
bad "--alternatives 17" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --alternatives 17
bad "--alternatives with interp" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --alternatives 1 --method interp
expect_stderr "single solution" "interp alternatives message"
expect_rc 2 "--alternatives to standard output" -- "$MF" inbetween -i "$SAMPLE" --keyframes 0,60 -o - --alternatives 1

# ------------------------------------------------------------ trajectory (issue 15, docs/CONSTRAINTS.md)
# The sample's hips path on frames 20..40 (BVH columns 7 and 9, cm), 15 cm to
# the side, facing +Z (the way it walks).
awk 'f { n++; fr = n - 1; if (fr >= 20 && fr <= 40) printf "%d,%.4f,%.4f,0,1\n", fr, $7 + 15 * sin(3.14159 * (fr - 19) / 22), $9 }
     /Frame Time/ { f = 1; print "frame,x,z,forward_x,forward_z" }' "$SAMPLE" >"$TMP/t.csv"
expect_rc 0 "fill --trajectory (nemf)" -- "$MF" --threads 1 fill -i "$SAMPLE" --gap 15:45 -o "$TMP/t.bvh" \
  --trajectory "$TMP/t.csv" --method nemf --report "$TMP/t-report.json"
expect_rc 0 "a trajectory keeps the known frames" -- "$DIFF" "$SAMPLE" "$TMP/t.bvh" --frames 0,14,45,60
grep -q '"rows": 21' "$TMP/t-report.json" && pass || fail "the report measures the trajectory's 21 rows"
printf '%s\n' "{\"task\": \"fill\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/bt.bvh\", \"gap\": [15, 45], \"method\": \"nemf\", \"trajectory\": \"$TMP/t.csv\", \"report\": \"$TMP/bt-report.json\"}" \
  "{\"task\": \"fill\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/bt2.bvh\", \"gap\": [15, 45], \"trajectory\": 3}" \
  >"$TMP/tjobs.jsonl"
# Without a method, a job with a trajectory runs the default for trajectories
# (nemf-refine with the bundled keyframe transformer), one without the plain default.
printf '%s\n' "{\"task\": \"fill\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/td.bvh\", \"gap\": [15, 45], \"trajectory\": \"$TMP/t.csv\"}" \
  "{\"task\": \"fill\", \"in\": \"$SAMPLE\", \"out\": \"$TMP/te.bvh\", \"gap\": [15, 45]}" >"$TMP/tdefault.jsonl"
expect_rc 0 "batch: default methods with and without a trajectory" -- "$MF" --threads 1 batch --json "$TMP/tdefault.jsonl"
grep -q '"line":1,.*"method":"nemf-refine"' "$TMP/out" && grep -q '"line":2,.*"method":"nemf-detail"' "$TMP/out" && pass ||
  fail "the default method is nemf-refine with a trajectory and nemf-detail without"
expect_rc 2 "batch with a trajectory (one bad line)" -- "$MF" --threads 1 batch "$TMP/tjobs.jsonl"
expect_stderr 'line 2: error: "trajectory" must be a string' "batch names a bad trajectory value"
cmp -s "$TMP/bt.bvh" "$TMP/t.bvh" && pass || fail "batch trajectory = --trajectory"
cmp -s "$TMP/bt-report.json" "$TMP/t-report.json" && pass || fail "batch trajectory report = --report"
bad "--trajectory with interp" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --trajectory "$TMP/t.csv" --method interp
expect_stderr "method 'interp' cannot follow a trajectory; the methods that can: nemf" "interp trajectory message"
printf 'frame,x,z,forward_x,forward_z\n5,0,0,0,1\n5,1,0,0,1\n' >"$TMP/t-bad.csv"
bad "--trajectory with a repeated frame" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --trajectory "$TMP/t-bad.csv" --method nemf
expect_stderr "t-bad.csv:3: frame 5 is given twice" "trajectory CSV error names the line"
bad "--trajectory file missing" inbetween -i "$SAMPLE" --keyframes 0,60 -o "$TMP/bad.bvh" --trajectory "$TMP/none.csv"
cp "$TMP/t.csv" "$TMP/tt.bvh"
bad "--trajectory is the output" fill -i "$SAMPLE" --gap 15:45 -o "$TMP/tt.bvh" --trajectory "$TMP/tt.bvh"
expect_stderr "is the trajectory file" "refuses to overwrite the trajectory file"

# ------------------------------------------------------------ the bad-input catalogue (issue 18, docs/RELIABILITY.md "Cases")
# Each case: exit code 2, a message naming the problem (and file:line for files),
# no output file. Every input file of the catalogue is checksummed before and
# compared after: no case may modify its input.
CAT="$TMP/cat"
mkdir -p "$CAT/dir" "$CAT/nodir-parent"
cp "$SAMPLE" "$CAT/walk.bvh"
: >"$CAT/empty.bvh"
head -n 3 "$SAMPLE" >"$CAT/cut-hierarchy.bvh"
awk '{ print } /^MOTION/ { exit }' "$SAMPLE" >"$CAT/cut-motion.bvh"
awk '{ print } /^Frames:/ { exit }' "$SAMPLE" >"$CAT/cut-frames.bvh"
awk '{ print } /^Frame Time:/ { on = 1; next } on { n++ } n == 30 { exit }' "$SAMPLE" >"$CAT/cut-data.bvh"
head -c -100 "$SAMPLE" >"$CAT/cut-value.bvh"
head -c 3000 "$SRC/models/motionfield-prior.mfm" >"$CAT/binary.bvh"
awk '/^Frame Time:/ { print; getline; $8 = "nan"; print; next } { print }' "$SAMPLE" >"$CAT/nan.bvh"
sed 's/^\([[:space:]]*OFFSET\) [^ ]*/\1 1e400/' "$SAMPLE" >"$CAT/overflow.bvh"
sed 's/^Frames: 61/Frames: 99999999999/' "$SAMPLE" >"$CAT/huge-frames.bvh"
awk 'BEGIN { print "HIERARCHY"; print "ROOT J0"; print "{"; print "OFFSET 0 0 0"; print "CHANNELS 1 Xrotation"
  for (d = 1; d <= 64; d++) { print "JOINT J" d; print "{"; print "OFFSET 0 1 0" }
  for (d = 1; d <= 64; d++) print "}"; print "}"; print "MOTION"; print "Frames: 1"; print "Frame Time: 0.1"; print "0" }' \
  >"$CAT/deep.bvh"
sums_before=$(cd "$CAT" && sha256sum ./*.bvh | sha256sum)
catalogue() {  # DESCRIPTION STDERR-PATTERN ARGS...
  local what=$1 pattern=$2
  shift 2
  bad "$what" "$@"
  expect_stderr "$pattern" "$what: message"
}
# BVH, every section truncated or broken.
catalogue "empty BVH" "empty.bvh:1: empty file" inbetween --in "$CAT/empty.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "BVH cut inside HIERARCHY" "cut-hierarchy.bvh:3: unexpected end of file inside joint" \
  inbetween --in "$CAT/cut-hierarchy.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "BVH cut after MOTION" "cut-motion.bvh:[0-9]*: unexpected end of file: expected 'Frames:'" \
  inbetween --in "$CAT/cut-motion.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "BVH cut after Frames:" "cut-frames.bvh:[0-9]*: unexpected end of file: expected 'Frame'" \
  inbetween --in "$CAT/cut-frames.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "BVH cut between frames" "cut-data.bvh:[0-9]*: unexpected end of file in motion data: expected 4392 values" \
  inbetween --in "$CAT/cut-data.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "BVH cut inside a frame" "cut-value.bvh:[0-9]*: unexpected end of file in motion data" \
  inbetween --in "$CAT/cut-value.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "binary garbage as BVH" "binary.bvh:1: expected HIERARCHY" inbetween --in "$CAT/binary.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
LC_ALL=C grep -q '[[:cntrl:]]' <(tr -d '\n' <"$TMP/err") && fail "control bytes of a binary BVH reached stderr" || pass
catalogue "NaN in the motion data" "nan.bvh:[0-9]*: non-finite value 'nan'" inbetween --in "$CAT/nan.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "an OFFSET of 1e400" "overflow.bvh:[0-9]*: .*out of range" inbetween --in "$CAT/overflow.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "Frames: 99999999999" "huge-frames.bvh:[0-9]*: Frames: 99999999999 exceeds the limit of 10000000" \
  inbetween --in "$CAT/huge-frames.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "joints nested 65 deep" "deep.bvh:[0-9]*: .*nested deeper than 64" inbetween --in "$CAT/deep.bvh" --keyframes 0,1 --out "$TMP/bad.bvh"
# Directories, devices and FIFOs as inputs.
catalogue "a directory as --in" "cannot read BVH file .*dir: it is a directory" inbetween --in "$CAT/dir" --keyframes 0,1 --out "$TMP/bad.bvh"
catalogue "/dev/zero as --model" "cannot read model file /dev/zero: it is a device, not a file" \
  --model /dev/zero inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh"
catalogue "a directory as --model" "cannot read model file .*dir: it is a directory" \
  --model "$CAT/dir" inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh"
catalogue "/dev/zero as --rig-map" "cannot read rig map file /dev/zero: it is a device, not a file" \
  --rig-map /dev/zero inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh"
catalogue "/dev/zero as --constraints" "cannot read constraints file /dev/zero: it is a device, not a file" \
  inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh" --constraints /dev/zero
catalogue "a directory as the batch file" "cannot read the batch file .*dir: it is a directory" batch "$CAT/dir"
mkfifo "$CAT/fifo"
(cat "$SAMPLE" >"$CAT/fifo" &)
expect_rc 0 "a FIFO as --in" -- timeout 20 "$MF" inbetween --in "$CAT/fifo" --keyframes 0,60 --out "$TMP/fifo.bvh" --method interp
cmp -s "$TMP/fifo.bvh" "$TMP/kf-interp.bvh" 2>/dev/null || expect_rc 0 "a FIFO as --in: the same frames" -- \
  "$DIFF" "$TMP/fifo.bvh" "$SAMPLE" --frames 0,60
(head -c 70M /dev/zero >"$CAT/fifo" 2>/dev/null &)
expect_rc 2 "a FIFO batch file past 64 MiB" -- timeout 60 "$MF" batch "$CAT/fifo"
expect_stderr "cannot read the batch file .*fifo: larger than the limit of 64 MiB" "FIFO past the limit: message"
rm -f "$CAT/fifo"
# A terminal as --in - (script(1) gives the command one on stdin): refused at once.
script -qec "timeout 20 \"$MF\" inbetween --in - --keyframes 0,60 --out \"$TMP/bad.bvh\" --method interp" /dev/null \
  </dev/null >"$TMP/err" 2>&1
[ $? -eq 2 ] && pass || fail "--in - on a terminal: exit code 2"
expect_stderr "cannot read BVH file /dev/stdin: it is a device, not a file" "--in - on a terminal: message"
expect_absent "$TMP/bad.bvh"
# Non-finite and absurd numbers on the command line.
catalogue "--fps nan" "the target fps must be finite and positive" resample --in "$SAMPLE" --fps nan --out "$TMP/bad.bvh"
catalogue "--fps inf" "the target fps must be finite and positive" resample --in "$SAMPLE" --fps inf --out "$TMP/bad.bvh"
catalogue "--fps -30" "the target fps must be finite and positive" resample --in "$SAMPLE" --fps -30 --out "$TMP/bad.bvh"
catalogue "--fps 1e300" "would give more than 10000000 frames" resample --in "$SAMPLE" --fps 1e300 --out "$TMP/bad.bvh"
catalogue "a keyframe past 2^31" "bad integer for --keyframes: '2147483648'" inbetween --in "$SAMPLE" --keyframes 0,2147483648 --out "$TMP/bad.bvh"
catalogue "--gap 1:1e9" "bad integer for --gap" fill --in "$SAMPLE" --gap 1:1e9 --out "$TMP/bad.bvh"
catalogue "--threads 100000" "--threads: Value 100000 not in range 1 to 1024" --threads 100000 inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh"
catalogue "--length-scale nan" "--units (--length-scale) must be positive, not nan" --length-scale nan inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh" --method interp
catalogue "--length-scale 0" "must be positive, not 0" --length-scale 0 inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh" --method interp
catalogue "--alternatives -1" "--alternatives: Value -1 not in range 0 to 16" inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh" --alternatives -1
catalogue "--max-iterations -1" "--max-iterations: Value -1 not in range 0 to 100000" fill --in "$SAMPLE" --gap 10:20 --out "$TMP/bad.bvh" --max-iterations -1
# Outputs: a directory, an existing file kept unchanged by a failing run.
catalogue "--out naming a directory" "cannot write .*dir: it is a directory" inbetween --in "$SAMPLE" --keyframes 0,60 --out "$CAT/dir" --method interp
[ -d "$CAT/dir" ] && [ -z "$(ls -A "$CAT/dir")" ] && pass || fail "--out naming a directory changed the directory"
printf 'an existing file\n' >"$TMP/keep.bvh"
for args in "inbetween --keyframes 0,99 --method interp" "resample --fps nan" "fill --gap 0:10" "inbetween --keyframes 0,60 --method magic"; do
  # shellcheck disable=SC2086
  expect_rc 2 "failing run ($args) onto an existing file" -- "$MF" $args --in "$SAMPLE" --out "$TMP/keep.bvh"
  [ "$(cat "$TMP/keep.bvh")" = "an existing file" ] && pass || fail "a failing run ($args) changed the existing output"
done
expect_rc 2 "a broken --model onto an existing file" -- "$MF" --model "$CAT/binary.bvh" inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/keep.bvh"
[ "$(cat "$TMP/keep.bvh")" = "an existing file" ] && pass || fail "a broken model changed the existing output"
[ "$(find "$TMP" -maxdepth 1 \( -name 'keep.bvh.tmp*' -o -name '.keep.bvh.*' \) | wc -l)" -eq 0 ] && pass || fail "a temporary file was left next to keep.bvh"
# Model files truncated, empty or with a flipped byte (the tiny model and its transformers).
if [ -x "$HELPER" ] && mkdir -p "$CAT/m" && "$HELPER" "$CAT/m/prior.mfm" --transformers; then
  head -c 1000 "$CAT/m/prior.mfm" >"$CAT/trunc.mfm"
  : >"$CAT/empty.mfm"
  cp "$CAT/m/prior.mfm" "$CAT/flip.mfm"
  printf '\x55' | dd of="$CAT/flip.mfm" bs=1 seek=5000 conv=notrunc 2>/dev/null
  catalogue "a truncated model" "trunc.mfm: truncated model file" --model "$CAT/trunc.mfm" inbetween --in "$SMALL" --keyframes 0,39 --out "$TMP/bad.bvh"
  catalogue "an empty model" "empty.mfm: not a motionfield model file" --model "$CAT/empty.mfm" inbetween --in "$SMALL" --keyframes 0,39 --out "$TMP/bad.bvh"
  catalogue "a model with a flipped byte" "flip.mfm: corrupted model file (checksum mismatch)" \
    --model "$CAT/flip.mfm" inbetween --in "$SMALL" --keyframes 0,39 --out "$TMP/bad.bvh"
  printf '\x55' | dd of="$CAT/m/motionfield-twostage.mfm" bs=1 seek=3000 conv=notrunc 2>/dev/null
  catalogue "a two-stage file with a flipped byte, --method detail" \
    "needs models/motionfield-twostage.mfm .*motionfield-twostage.mfm: corrupted model file (checksum mismatch)" \
    --model "$CAT/m/prior.mfm" inbetween --in "$SMALL" --keyframes 0,20,39 --out "$TMP/bad.bvh" --method detail
  cp "$CAT/m/motionfield-citl.mfm" "$CAT/citl.mfm"
  head -c 5000 "$CAT/citl.mfm" >"$CAT/m/motionfield-citl.mfm"
  catalogue "--citl naming a truncated file" "truncated" \
    --model "$CAT/m/prior.mfm" --citl "$CAT/m/motionfield-citl.mfm" inbetween --in "$SMALL" --keyframes 0,20,39 --out "$TMP/bad.bvh" --method citl
else
  fail "mf_capi_tiny_model not built or failed: the model-file cases could not run"
fi
# Path CSVs: cut, binary, overflowing, too many points (renav needs a model: the tiny one).
if [ -n "$TINY" ]; then
  printf 'x,z\n0,0\n0.5,0.1\n1,' >"$CAT/cut.csv"
  head -c 2000 "$SRC/models/motionfield-prior.mfm" >"$CAT/binary.csv"
  printf '0,0\n1e400,1\n' >"$CAT/overflow.csv"
  awk 'BEGIN { for (i = 0; i <= 1000000; i++) printf "%d,0\n", i }' >"$CAT/many.csv"
  catalogue "a path CSV cut in its last line" "cut.csv:4:" --model "$TINY" renav --in "$SMALL" --path "$CAT/cut.csv" --out "$TMP/bad.bvh"
  catalogue "binary garbage as a path CSV" "binary.csv:1:" --model "$TINY" renav --in "$SMALL" --path "$CAT/binary.csv" --out "$TMP/bad.bvh"
  catalogue "1e400 in a path CSV" "overflow.csv:2:" --model "$TINY" renav --in "$SMALL" --path "$CAT/overflow.csv" --out "$TMP/bad.bvh"
  catalogue "a path of 1000001 points" "more than 1000000 points" --model "$TINY" renav --in "$SMALL" --path "$CAT/many.csv" --out "$TMP/bad.bvh"
  catalogue "/dev/zero as --path" "cannot read path file /dev/zero: it is a device, not a file" \
    --model "$TINY" renav --in "$SMALL" --path /dev/zero --out "$TMP/bad.bvh"
  catalogue "a directory as --polyline" "cannot read path file .*dir: it is a directory" \
    --model "$TINY" renav --in "$SMALL" --polyline "$CAT/dir" --out "$TMP/bad.bvh"
fi
# Batch: bad lines of every kind; the good jobs before and after them still run.
mkdir -p "$CAT/batch"
cp "$SAMPLE" "$CAT/batch/walk.bvh"
{
  echo '{"task": "inbetween", "in": "walk.bvh", "out": "j1.bvh", "keyframes": [0, 60], "method": "interp"}'
  head -c 3000 "$SRC/models/motionfield-prior.mfm" | tr '\n' ' '
  echo
  head -c 100000 /dev/zero | tr '\0' '['
  echo
  echo '{"task": "resample", "in": "walk.bvh", "out": "j4.bvh", "fps": 1e400}'
  echo '{"task": "resample", "in": "walk.bvh", "out": "j5.bvh", "fps": 1e300}'
  echo '{"task": "inbetween", "in": "walk.bvh", "out": "j6.bvh", "keyframes": [0, 1e20]}'
  echo '{}'
  echo '{"task": "inbetween", "in": "../dir", "out": "j8.bvh", "keyframes": [0, 60]}'
  echo '{"task": "inbetween", "in": "walk.bvh", "out": "nodir/j9.bvh", "keyframes": [0, 60]}'
  echo '{"task": "inbetween", "in": "walk.bvh", "out": "j10.bvh", "keyframes": [0, 30, 60], "method": "interp"}'
  printf '{"task": "inbetween", "in": "walk.bvh", "out": "j11.bvh", "keyf'
} >"$CAT/batch/bad.jsonl"
in_dir "$CAT/batch" expect_rc 2 "batch with bad lines of every kind" -- "$MF" batch bad.jsonl
expect_stderr "line 2: error: invalid JSON: column 1:" "batch: a binary line"
expect_stderr "line 3: error: invalid JSON: column 65: nesting deeper than 64 levels" "batch: deep nesting"
expect_stderr "line 4: error: invalid JSON: column [0-9]*: number out of range: 1e400" "batch: 1e400"
expect_stderr "line 5: error: resampling 61 frames from 30 to 1e+300 fps would give more than 10000000 frames" "batch: fps 1e300"
expect_stderr 'line 6: error: "keyframes" item 1 must be an integer, not 1e+20' "batch: keyframe 1e20"
expect_stderr 'line 7: error: missing key "task"' "batch: an empty object"
expect_stderr "line 8: error: cannot read BVH file ../dir: it is a directory" "batch: a directory as in"
expect_stderr "line 9: error: cannot write nodir/j9.bvh: directory nodir does not exist" "batch: an output directory that does not exist"
expect_stderr "line 11: error: invalid JSON: .*missing closing quote" "batch: a last line cut short"
expect_stderr "11 jobs, 2 ok, 9 failed" "batch summary"
expect_frames "$CAT/batch/j1.bvh" "$N"
expect_frames "$CAT/batch/j10.bvh" "$N"
[ "$(find "$CAT/batch" -name 'j*.bvh' | wc -l)" -eq 2 ] && pass || fail "a failed batch job left an output"
# Inputs are never modified.
[ "$(cd "$CAT" && sha256sum ./*.bvh | sha256sum)" = "$sums_before" ] && pass || fail "a catalogue case modified its input"
cmp -s "$CAT/batch/walk.bvh" "$SAMPLE" && pass || fail "batch modified its input"

# ------------------------------------------------------------ outputs and clients (issue 52, docs/RELIABILITY.md)
# Every output goes through the library's one writer (mf_output_set): no two
# outputs of a job or a batch, and no output and input, are one file; devices
# are written in place; a failure names its reason and leaves no output behind.
OUT="$TMP/outputs"
mkdir -p "$OUT"
cp "$SAMPLE" "$OUT/in.bvh"
# 96: --report naming --out is refused before anything runs; an existing file there is kept.
in_dir "$OUT" expect_rc 2 "--report naming --out" -- "$MF" inbetween --in in.bvh --keyframes 0,60 --out o.bvh \
  --report o.bvh --method interp
expect_stderr "the report o.bvh is also the output o.bvh: refusing to write one file twice" "--report = --out: message"
expect_absent "$OUT/o.bvh"
printf 'mine\n' >"$OUT/o.bvh"
in_dir "$OUT" expect_rc 2 "--report naming an existing --out" -- "$MF" inbetween --in in.bvh --keyframes 0,60 \
  --out o.bvh --report ./o.bvh --method interp
[ "$(cat "$OUT/o.bvh")" = mine ] && pass || fail "--report = --out changed the existing output"
rm -f "$OUT/o.bvh"
in_dir "$OUT" expect_rc 2 "--report naming the input" -- "$MF" inbetween --in in.bvh --keyframes 0,60 --out o.bvh \
  --report in.bvh --method interp
expect_stderr "the report in.bvh is the input in.bvh: refusing to overwrite it" "--report = --in: message"
cmp -s "$OUT/in.bvh" "$SAMPLE" && pass || fail "--report = --in changed the input"
# 97: the report beside a user's r.json.tmp: that file is never touched, no temporary file is left.
printf 'mine\n' >"$OUT/r.json.tmp"
in_dir "$OUT" expect_rc 0 "--report beside a user's r.json.tmp" -- "$MF" inbetween --in in.bvh --keyframes 0,60 \
  --out t.bvh --report r.json --method interp
[ "$(cat "$OUT/r.json.tmp")" = mine ] && pass || fail "the user's r.json.tmp was changed"
grep -q '"solutions"' "$OUT/r.json" && pass || fail "--report beside r.json.tmp: the report"
[ "$(find "$OUT" -name '.*.tmp' | wc -l)" -eq 0 ] && pass || fail "a temporary file was left behind"
# 98: a report the system cannot write (a read-only directory; /proc as root): the reason, and the motion not left behind.
if [ "$(id -u)" -ne 0 ]; then
  mkdir -p "$OUT/ro" && chmod 555 "$OUT/ro"
  RO="$OUT/ro/r.json"
else
  RO=/proc/motionfield-cli-test-report.json
fi
in_dir "$OUT" expect_rc 2 "--report into a read-only directory" -- "$MF" inbetween --in in.bvh --keyframes 0,60 \
  --out m.bvh --report "$RO" --method interp
expect_stderr "cannot write $RO: [A-Z]" "--report into a read-only directory: the reason"
expect_absent "$OUT/m.bvh"
# 99: devices, for every output kind: written in place, a full one fails with the reason and nothing is left.
ln -s /dev/null "$OUT/null.glb"
ln -s /dev/null "$OUT/null.gltf"
in_dir "$OUT" expect_rc 0 "--report /dev/null" -- "$MF" inbetween --in in.bvh --keyframes 0,60 --out d.bvh \
  --report /dev/null --method interp
in_dir "$OUT" expect_rc 0 "glTF onto /dev/null (.glb)" -- "$MF" export in.bvh null.glb
in_dir "$OUT" expect_rc 0 "glTF onto /dev/null (.gltf)" -- "$MF" export in.bvh null.gltf
[ -c /dev/null ] && [ -L "$OUT/null.glb" ] && pass || fail "an output replaced /dev/null or the link to it"
rm -f "$OUT/d.bvh"
if [ -c /dev/full ]; then
  ln -s /dev/full "$OUT/full.glb"
  ln -s /dev/full "$OUT/full.gltf"
  for args in "inbetween --keyframes 0,60 --method interp" "fill --gap 10:20 --method interp" \
    "resample --fps 60 --method cubic"; do
    # shellcheck disable=SC2086
    in_dir "$OUT" expect_rc 2 "$args --out /dev/full" -- "$MF" $args --in in.bvh --out /dev/full
    expect_stderr "cannot write /dev/full: No space left on device" "$args --out /dev/full: message"
  done
  for name in full.glb full.gltf; do
    in_dir "$OUT" expect_rc 2 "export onto a full device ($name)" -- "$MF" export in.bvh "$name"
    expect_stderr "cannot write $name: No space left on device" "export onto a full device ($name): message"
  done
  in_dir "$OUT" expect_rc 2 "--report /dev/full" -- "$MF" inbetween --in in.bvh --keyframes 0,60 --out d.bvh \
    --report /dev/full --method interp
  expect_stderr "cannot write /dev/full: No space left on device" "--report /dev/full: message"
  expect_absent "$OUT/d.bvh"
  printf '%s\n' '{"task": "inbetween", "in": "in.bvh", "out": "j.bvh", "keyframes": [0, 60], "method": "interp", "report": "/dev/full"}' \
    '{"task": "resample", "in": "in.bvh", "out": "full.glb", "fps": 60, "method": "cubic"}' >"$OUT/full.jsonl"
  in_dir "$OUT" expect_rc 2 "batch outputs onto a full device" -- "$MF" batch full.jsonl
  expect_stderr "line 1: error: cannot write /dev/full: No space left on device" "batch: report onto /dev/full"
  expect_stderr "line 2: error: cannot write full.glb: No space left on device" "batch: glTF onto /dev/full"
  expect_absent "$OUT/j.bvh"
  if [ -n "$TINY" ]; then
    ln -s /dev/full "$OUT/a_1.bvh"
    in_dir "$OUT" expect_rc 2 "an alternative onto a full device" -- "$MF" --model "$TINY" --threads 1 inbetween \
      --in "$SMALL" --keyframes 0,39 --out a.bvh --alternatives 1 --method nemf --max-iterations 1
    expect_stderr "cannot write a_1.bvh: No space left on device" "an alternative onto a full device: message"
    expect_absent "$OUT/a.bvh"
  fi
  [ -c /dev/full ] && pass || fail "/dev/full is no longer a character device"
fi
# 100: batch: a report naming its own output, another job's output, the input; a job reading another's output.
printf '%s\n' '{"task": "inbetween", "in": "in.bvh", "out": "b1.bvh", "keyframes": [0, 60], "method": "interp", "report": "b1.bvh"}' \
  '{"task": "inbetween", "in": "in.bvh", "out": "b2.bvh", "keyframes": [0, 60], "method": "interp", "report": "b2.json"}' \
  '{"task": "inbetween", "in": "in.bvh", "out": "b3.bvh", "keyframes": [0, 60], "method": "interp", "report": "./b2.bvh"}' \
  '{"task": "inbetween", "in": "b2.bvh", "out": "b4.bvh", "keyframes": [0, 60], "method": "interp"}' \
  '{"task": "inbetween", "in": "in.bvh", "out": "b5.bvh", "keyframes": [0, 60], "method": "interp", "report": "in.bvh"}' \
  '{"task": "inbetween", "in": "in.bvh", "out": "b6.bvh", "keyframes": [0, 60], "method": "interp", "report": "b2.json"}' \
  >"$OUT/b.jsonl"
in_dir "$OUT" expect_rc 2 "batch: outputs that are other outputs or inputs" -- "$MF" batch b.jsonl
expect_stderr "line 1: error: the report b1.bvh is also the output b1.bvh" "batch: report = out"
expect_stderr "line 3: error: line 2 already writes ./b2.bvh: refusing to overwrite another job's output" \
  "batch: a report naming another job's output"
expect_stderr "line 4: error: line 2 writes b2.bvh, which this job reads" "batch: a job reading another's output"
expect_stderr "line 5: error: the report in.bvh is the input in.bvh" "batch: a report naming the input"
expect_stderr "line 6: error: line 2 already writes b2.json" "batch: two reports into one file"
expect_stderr "6 jobs, 1 ok, 5 failed" "batch: outputs that are other outputs: summary"
for f in b1.bvh b3.bvh b4.bvh b5.bvh b6.bvh; do expect_absent "$OUT/$f"; done
grep -q '"solutions"' "$OUT/b2.json" && pass || fail "batch: the good job's report"
cmp -s "$OUT/in.bvh" "$SAMPLE" && pass || fail "batch: an output changed the input"
# 101: strict readers: a duplicate key in a constraints file; a rig map over its limit in every command.
printf '{"keys": [{"frame": 30, "joints": ["Hips"]}], "keys": []}\n' >"$OUT/dup.json"
catalogue "a constraints file with a duplicate key" 'dup.json: duplicate key "keys" in the top-level object' \
  inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh" --constraints "$OUT/dup.json" --method interp
{ printf '{"Hips": "Hips"'; head -c 1100000 /dev/zero | tr '\0' ' '; printf '}\n'; } >"$OUT/big-map.json"
catalogue "rig --rig-map over 1 MiB" "cannot read rig map file .*big-map.json: larger than the limit of 1 MiB" \
  --rig-map "$OUT/big-map.json" rig "$SAMPLE"
catalogue "inbetween --rig-map over 1 MiB" "larger than the limit of 1 MiB" \
  --rig-map "$OUT/big-map.json" inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh" --method nemf
# 102: the method against the task before the rig.
if [ -n "$TINY" ]; then
  catalogue "--method prior on a clip the model cannot map" "method 'prior' does not do in-betweening" \
    --model "$TINY" inbetween --in "$SAMPLE" --keyframes 0,60 --out "$TMP/bad.bvh" --method prior
fi
# 103: every combination of --out, --alternatives and --report over names that overlap (another
# spelling, a symbolic link, the input, an alternative's name): refused with nothing written, or
# every output holds what it should and the input is unchanged.
if [ -n "$TINY" ]; then
  COMBO="$OUT/combo"
  mkdir -p "$COMBO"
  cp "$SMALL" "$COMBO/in.bvh"
  ln -s o.bvh "$COMBO/link.bvh"
  canon() { local n=${1#./}; [ "$n" = link.bvh ] && n=o.bvh; echo "$n"; }
  alt_of() { local n=$1 d=""; case $n in */*) d=${n%/*}/; n=${n##*/};; esac; echo "$d${n%.*}_1.${n##*.}"; }
  combos=0 refused=0
  for out in o.bvh ./o.bvh link.bvh in.bvh o_1.bvh; do
    for report in "" o.bvh ./o_1.bvh r.json in.bvh link.bvh link_1.bvh; do
      for alts in 0 1; do
        combos=$((combos + 1))
        (cd "$COMBO" && rm -f o.bvh o_1.bvh o_1_1.bvh link_1.bvh r.json .*.tmp)
        set -- --model "$TINY" --threads 1 inbetween --in in.bvh --keyframes 0,39 --out "$out" --method nemf \
          --max-iterations 1 --alternatives "$alts"
        [ -n "$report" ] && set -- "$@" --report "$report"
        outputs=("$out")
        [ "$alts" -eq 1 ] && outputs+=("$(alt_of "$out")")
        [ -n "$report" ] && outputs+=("$report")
        expected=0
        seen=" in.bvh "
        for o in "${outputs[@]}"; do
          c=$(canon "$o")
          case "$seen" in *" $c "*) expected=2 ;; esac
          seen="$seen$c "
        done
        what="--out $out --alternatives $alts --report '$report'"
        in_dir "$COMBO" expect_rc "$expected" "$what" -- "$MF" "$@"
        if [ "$expected" -eq 2 ]; then
          refused=$((refused + 1))
          expect_stderr "refusing" "$what: message"
          [ -z "$(cd "$COMBO" && ls -A | grep -v -x -e in.bvh -e link.bvh)" ] && pass || fail "$what wrote an output"
        else
          for o in "${outputs[@]}"; do
            f="$COMBO/$o"
            if [ "$o" = "$report" ]; then
              grep -q '"solutions"' "$f" && pass || fail "$what: $o does not hold the report"
            else
              [ "$(frames_of "$f")" = 40 ] && pass || fail "$what: $o does not hold a motion"
            fi
          done
        fi
        cmp -s "$COMBO/in.bvh" "$SMALL" && pass || fail "$what changed the input"
        [ -L "$COMBO/link.bvh" ] && pass || fail "$what replaced the link"
      done
    done
  done
  [ "$refused" -gt 10 ] && [ "$refused" -lt "$combos" ] && pass || fail "combinations: $refused of $combos refused"
fi

echo "cli_test: $((checks - failures)) of $checks checks passed"
[ "$failures" -eq 0 ]
