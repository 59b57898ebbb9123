#!/usr/bin/env bash
# `make asan`: builds everything with AddressSanitizer + UndefinedBehaviorSanitizer
# (the default compiler, g++ as in CI; MF_SANITIZE=address,undefined) into
# build-asan and runs the CTest suite there, under `nice -n 15`.
#   scripts/asan.sh [CTEST ARGS...]     e.g. scripts/asan.sh -R 'Bvh|Capi|fuzz'
# Tests that load libmotionfield.so into an uninstrumented program (the Python
# ones and the Blender add-on's: /usr/bin/python3 and Blender would need the
# ASan runtime preloaded: "ASan runtime does not come first in initial library
# list") and the package test (it rebuilds against the install without the
# sanitizer flags) are left out. Options and suppressions: scripts/sanitizers/.
# Environment: ASAN_BUILD (build-asan), JOBS (2).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${ASAN_BUILD:-build-asan}
JOBS=${JOBS:-2}
source scripts/sanitizers/env.sh
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DMF_SANITIZE=address,undefined
fi
start=$(date +%s)
nice -n 15 cmake --build "$BUILD" -j "$JOBS"
built=$(date +%s)
cd "$BUILD"
status=0
nice -n 15 ctest --output-on-failure -j "$JOBS" -E 'python|blender|capi_package' "$@" || status=$?
echo "asan: build $((built - start)) s, tests $(($(date +%s) - built)) s, ctest status $status"
exit $status
