#!/usr/bin/env bash
# The README's install of the add-on zip: make_zip.py bundles the built
# library and the models, Blender installs the zip into a fresh user scripts
# folder and enables it, with no MOTIONFIELD_* variable set: the add-on must
# find its bundled package, library and default model on its own.
# Usage: zip_test.sh SOURCE_DIR LIBRARY WORK_DIR BLENDER
set -euo pipefail
src=$1 lib=$2 work=$3 blender=$4
rm -rf "$work" && mkdir -p "$work/scripts"
/usr/bin/python3 "$src/integrations/blender/make_zip.py" "$work/motionfield_blender.zip" --library "$lib"
env -u MOTIONFIELD_PYTHON -u MOTIONFIELD_LIBRARY -u MF_MODEL -u PYTHONPATH \
  BLENDER_USER_SCRIPTS="$work/scripts" MF_BLENDER_ZIP="$work/motionfield_blender.zip" \
  "$blender" -b --factory-startup --python-exit-code 1 --python "$src/integrations/blender/tests/zip_install.py"
