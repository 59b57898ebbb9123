#!/usr/bin/env bash
# Stands in for blender when CMake did not find it: the Blender tests fail.
echo "blender was not found when CMake configured: run scripts/install-deps.sh (it installs blender), then reconfigure" >&2
exit 1
