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

# Every method offered runs from the zip (a short budget: they run, not converge).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import walk_session  # noqa: E402

s = bpy.context.scene.motionfield
offered = {kind: [i[0] for i in motionfield_blender._method_items(kind)(s, bpy.context)]
           for kind in ("complete", "resample")}
completes = [m.name for m in mf.methods() if m.completes]
if offered["complete"] != ["DEFAULT"] + completes or len(completes) != 14:
    errors.append("the zip does not offer every in-betweening method: %s" % offered["complete"])
obj, motion, keys = walk_session.setup(mf, fps=30, container=False)
action = obj.animation_data.action
s.max_iterations = 2
for kind, op in (("complete", bpy.ops.motionfield.inbetween), ("resample", bpy.ops.motionfield.resample)):
    for name in offered[kind]:
        setattr(s, "method" if kind == "complete" else "resample_method", name)
        s.source_fps = 60.0
        obj.animation_data.action = action
        try:
            if op('EXEC_DEFAULT') != {'FINISHED'}:
                errors.append("%s with %s did not finish" % (op.idname_py(), name))
        except RuntimeError as e:
            errors.append("%s with %s: %s" % (op.idname_py(), name, e))
        bpy.ops.motionfield.clear_generated('EXEC_DEFAULT')
print("methods run from the zip:", offered)
addon_utils.disable("motionfield_blender")
if hasattr(bpy.types.Scene, "motionfield"):
    errors.append("disabling did not unregister")
print("\n".join(errors) or "zip install: ok")
sys.exit(1 if errors else 0)
