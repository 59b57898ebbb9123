#!/usr/bin/env bash
# Stands in for xvfb-run when CMake did not find it: the panel test fails.
echo "xvfb-run was not found when CMake configured: run scripts/install-deps.sh (it installs xvfb), then reconfigure" >&2
exit 1
