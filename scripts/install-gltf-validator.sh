#!/usr/bin/env bash
# Installs the Khronos glTF validator (npm package gltf-validator, pinned) under
# PREFIX (the build tree's tools/ folder), for the glTF tests
# (tests/gltf_validator_test.sh). Needs node and npm (scripts/install-deps.sh
# installs them) and the npm registry; does nothing if that version is there.
#   usage: scripts/install-gltf-validator.sh PREFIX
set -euo pipefail

VERSION=2.0.0-dev.3.10
if [ $# -ne 1 ]; then
  echo "usage: $0 PREFIX" >&2
  exit 2
fi
PREFIX=$1
for tool in node npm; do
  if ! command -v "$tool" >/dev/null; then
    echo "install-gltf-validator: $tool not found (scripts/install-deps.sh installs it)" >&2
    exit 1
  fi
done
installed=$(node -e "try { console.log(require('$PREFIX/node_modules/gltf-validator/package.json').version) } catch (e) {}")
if [ "$installed" = "$VERSION" ]; then
  echo "install-gltf-validator: gltf-validator $VERSION already in $PREFIX"
  exit 0
fi
mkdir -p "$PREFIX"
npm install --prefix "$PREFIX" --no-audit --no-fund --no-save --loglevel=error "gltf-validator@$VERSION"
echo "install-gltf-validator: gltf-validator $VERSION installed in $PREFIX"
