#!/usr/bin/env bash
# The README's install, in a fresh venv without network: pip installs
# ./python against Debian's setuptools (bundling the built library and the
# bundled model), then the installed package runs a small task with nothing
# else set: no PYTHONPATH, MOTIONFIELD_LIBRARY or MF_MODEL, outside the source tree.
#   usage: venv_test.sh SOURCE_DIR LIBRARY WORK_DIR
set -euo pipefail
src=$1
lib=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
venv=$work/venv
unset PYTHONPATH MF_MODEL PYTHONDONTWRITEBYTECODE

echo "== python3 -m venv --system-site-packages"
/usr/bin/python3 -m venv --system-site-packages "$venv"

echo "== pip install --no-index --no-build-isolation ./python (bundling $lib)"
(cd "$src" && MOTIONFIELD_LIBRARY="$lib" MOTIONFIELD_BUNDLE=1 "$venv/bin/pip" install --no-index --no-build-isolation \
  --no-cache-dir --disable-pip-version-check --quiet ./python)
# The source tree stays clean.
for d in "$src/python/build" "$src/python/motionfield.egg-info"; do
  [ ! -e "$d" ] || { echo "pip left $d in the source tree"; exit 1; }
done

echo "== the installed package"
unset MOTIONFIELD_LIBRARY
cd "$work"
"$venv/bin/python" - "$venv" "$src" <<'PY'
import importlib.metadata
import os
import re
import sys

venv, src = (os.path.realpath(p) for p in sys.argv[1:3])
import motionfield as mf

def inside(path, root):
    return os.path.realpath(path).startswith(root + os.sep)

package = os.path.dirname(mf.__file__)
assert inside(package, venv), package
assert inside(mf.library_path(), venv), mf.library_path()
assert mf.library_path() == os.path.join(package, "lib", "libmotionfield.so.0"), mf.library_path()
assert mf.default_model_path() == os.path.join(package, "share", "motionfield", "motionfield-prior.mfm"), \
    mf.default_model_path()
assert os.path.isfile(os.path.join(package, "py.typed"))
with open(os.path.join(src, "CMakeLists.txt")) as f:
    cmake_version = re.search(r"project\(\s*motionfield\s+VERSION\s+([0-9.]+)", f.read()).group(1)
assert mf.__version__ == cmake_version == importlib.metadata.version("motionfield"), \
    (mf.__version__, cmake_version, importlib.metadata.version("motionfield"))
model = mf.default_model()
assert all(v["loaded"] for v in model.describe()["inbetweeners"].values()), model.describe()  # every transformer came along

mf.set_num_threads(2)
walk = mf.Motion.load_bvh(os.path.join(src, "samples", "walk_keyframes.bvh"))
clip = mf.Motion.from_arrays(walk.rotations[:21], walk.root_positions[:21], walk.fps, like=walk)
keys = [0, 10, 20]
# The two-stage transformer from the bundled files (the default method,
# nemf-detail, starts from it; test_same_as_cli.py runs that one).
assert mf.default_method() == "nemf-detail", mf.default_method()
out = mf.inbetween(clip, keys, method="detail")
assert out.frame_count == 21
assert (out.rotations[keys] == clip.rotations[keys]).all()
assert not (out.rotations[5] == mf.inbetween(clip, keys, method="interp").rotations[5]).all()
print("venv: motionfield %s, %s, model %s: %d frames" % (
    mf.__version__, mf.library_path(), mf.default_model_path(), out.frame_count))
PY
echo "venv test ok"
