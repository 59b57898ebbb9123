"""Run by zip_test.sh inside Blender: installs and enables the add-on zip,
then checks it runs on its bundled package, library and model."""
import os
import sys

import addon_utils
import bpy

bpy.ops.preferences.addon_install(filepath=os.environ["MF_BLENDER_ZIP"])
addon_utils.enable("motionfield_blender", default_set=True, handle_error=None)
import motionfield_blender  # noqa: E402
from motionfield_blender import engine  # noqa: E402

errors = []
vendor = os.path.join(os.path.dirname(motionfield_blender.__file__), "_vendor")
if not os.environ["BLENDER_USER_SCRIPTS"] in motionfield_blender.__file__:
    errors.append("the add-on was not installed into the user scripts: %s" % motionfield_blender.__file__)
mf = engine.load()
for what, path in (("package", mf.__file__), ("library", mf.library_path()), ("model", mf.default_model_path())):
    print(what, path)
    if not path or not os.path.realpath(path).startswith(os.path.realpath(vendor)):
        errors.append("the %s is not the bundled one: %s" % (what, path))
if not hasattr(bpy.types.Scene, "motionfield") or not hasattr(bpy.ops.motionfield, "inbetween"):
    errors.append("the add-on did not register its settings and operators")
bpy.context.scene.motionfield.method = "nemf-detail"  # the enum lists the library's methods
if bpy.context.scene.motionfield.method != "nemf-detail":
    errors.append("method enum: %s" % bpy.context.scene.motionfield.method)
engine.model()  # the default (bundled) model loads
addon_utils.disable("motionfield_blender")
if hasattr(bpy.types.Scene, "motionfield"):
    errors.append("disabling did not unregister")
print("\n".join(errors) or "zip install: ok")
sys.exit(1 if errors else 0)
