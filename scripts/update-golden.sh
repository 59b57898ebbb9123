#!/usr/bin/env bash
# Regenerates tests/golden/shipped_models.txt: runs the golden tests of the
# shipped models (tests/capi/capi_golden_test.cc) at one thread and stores the
# sketches of their outputs and the checksums of the files they depend on. Run it
# after a deliberate change (a retrained model in models/, a changed method),
# then review and commit the file with the change.
#   usage: scripts/update-golden.sh [BUILD_DIR]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
cmake --build "$build" --target mf_capi_tests
MF_UPDATE_GOLDEN=1 "$build/capi/mf_capi_tests" --gtest_filter=CApiGolden.OneThreadMatchesTheStoredOutputs
git --no-pager diff --stat -- tests/golden/shipped_models.txt
