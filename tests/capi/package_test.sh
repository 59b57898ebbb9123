#!/usr/bin/env bash
# Installs motionfield (the "motionfield" install component) into a temporary
# prefix and uses it from outside the build tree: the CLI, an external C
# project (samples/c) built with find_package(motionfield) and with pkg-config,
# the C++ sample (samples/cpp, motionfield.hpp) with find_package, and the
# Python package.
#   usage: package_test.sh BUILD_DIR SOURCE_DIR C_COMPILER CXX_COMPILER
set -euo pipefail
build=$1
src=$2
cc=$3
cxx=$4
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mf-package.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
sample=$src/samples/walk_keyframes.bvh
unset MOTIONFIELD_LIBRARY MF_MODEL

step() { echo "== $*"; }

step "install"
cmake --install "$build" --prefix "$prefix" --component motionfield >"$tmp/install.log"
lib=$(find "$prefix" -name 'libmotionfield.so.*.*' | head -1)
[ -n "$lib" ] || { echo "libmotionfield.so.X.Y not installed"; cat "$tmp/install.log"; exit 1; }
libdir=$(dirname "$lib")
for f in "$libdir/libmotionfield.so" "$libdir/libmotionfield.so.0" "$prefix/include/motionfield.h" "$prefix/include/motionfield.hpp" \
         "$prefix/bin/motionfield" "$libdir/cmake/motionfield/motionfieldConfig.cmake" \
         "$libdir/cmake/motionfield/motionfieldConfigVersion.cmake" "$libdir/cmake/motionfield/motionfieldTargets.cmake" \
         "$libdir/pkgconfig/motionfield.pc" "$prefix/lib/python3/dist-packages/motionfield/__init__.py"; do
  [ -e "$f" ] || { echo "missing after install: $f"; exit 1; }
done
if [ -f "$src/models/motionfield-prior.mfm" ]; then
  [ -f "$prefix/share/motionfield/motionfield-prior.mfm" ] || { echo "default model not installed"; exit 1; }
fi

step "the installed CLI"
"$prefix/bin/motionfield" --version
"$prefix/bin/motionfield" --threads 1 inbetween --in "$sample" --keyframes 0,30,60 --out "$tmp/cli.bvh"
[ "$(awk '/^Frames:/ { print $2 }' "$tmp/cli.bvh")" = 61 ]
used=$(ldd "$prefix/bin/motionfield" | awk '$1 == "libmotionfield.so.0" { print $3 }')
[ -n "$used" ] && [ "$(readlink -f "$used")" = "$(readlink -f "$libdir/libmotionfield.so.0")" ] \
  || { echo "the installed CLI uses '$used', not the installed library"; exit 1; }

step "an external CMake project: find_package(motionfield)"
cmake -S "$src/samples/c" -B "$tmp/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" \
  -DCMAKE_BUILD_TYPE=Release >"$tmp/cmake.log" || { cat "$tmp/cmake.log"; exit 1; }
cmake --build "$tmp/cmake-build" >"$tmp/build.log" || { cat "$tmp/build.log"; exit 1; }
"$tmp/cmake-build/inbetween" "$sample" "$tmp/cmake.bvh"
[ "$(awk '/^Frames:/ { print $2 }' "$tmp/cmake.bvh")" = 61 ]

step "an external C++ project on motionfield.hpp: find_package(motionfield)"
cmake -S "$src/samples/cpp" -B "$tmp/cmake-build-cpp" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" \
  -DCMAKE_BUILD_TYPE=Release >"$tmp/cmake-cpp.log" || { cat "$tmp/cmake-cpp.log"; exit 1; }
cmake --build "$tmp/cmake-build-cpp" >"$tmp/build-cpp.log" || { cat "$tmp/build-cpp.log"; exit 1; }
"$tmp/cmake-build-cpp/inbetween" "$sample" "$tmp/cmake-cpp.bvh"
[ "$(awk '/^Frames:/ { print $2 }' "$tmp/cmake-cpp.bvh")" = 61 ]

step "an external project with pkg-config"
export PKG_CONFIG_PATH="$libdir/pkgconfig"
pkg-config --exists --print-errors motionfield
echo "motionfield $(pkg-config --modversion motionfield): $(pkg-config --cflags --libs motionfield)"
[ "$(pkg-config --modversion motionfield)" = "$(grep -o '^#define MF_VERSION_STRING "[^"]*"' "$prefix/include/motionfield.h" | cut -d'"' -f2)" ]
# shellcheck disable=SC2046
"$cc" -std=c89 -pedantic -Wall -Wextra -Werror $(pkg-config --cflags motionfield) "$src/samples/c/inbetween.c" \
  -o "$tmp/pc-inbetween" $(pkg-config --libs motionfield) -Wl,-rpath,"$(pkg-config --variable=libdir motionfield)"
"$tmp/pc-inbetween" "$sample" "$tmp/pc.bvh"
[ "$(awk '/^Frames:/ { print $2 }' "$tmp/pc.bvh")" = 61 ]

step "the installed Python package (no MOTIONFIELD_LIBRARY: the library next to it)"
(cd "$tmp" && PYTHONPATH="$prefix/lib/python3/dist-packages" PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 - "$sample" "$lib" "$prefix" <<'PY'
import os, sys
import motionfield as mf
assert os.path.realpath(mf.library_path()) == os.path.realpath(sys.argv[2]), (mf.library_path(), sys.argv[2])
assert os.path.isfile(os.path.join(os.path.dirname(mf.__file__), "py.typed"))
# The default model is the installed one (the CLI's too).
installed = os.path.join(sys.argv[3], "share", "motionfield", "motionfield-prior.mfm")
if os.path.isfile(installed):
    assert os.path.realpath(mf.default_model_path()) == os.path.realpath(installed), mf.default_model_path()
m = mf.Motion.load_bvh(sys.argv[1])
out = mf.resample(m, 60.0)
assert out.frame_count == 121, out.frame_count
print("python:", mf.version(), "->", mf.library_path())
PY
)
echo "package test ok"
