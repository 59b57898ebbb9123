"""The issue's "Done when" numbers: the sample walk with a key every 20
frames in a 24 fps scene (imported with a static joint_Root container as
Blender's importer makes it), In-between with the default settings (the
root found by the add-on) against Blender's own interpolation of the same
keys, both measured against the full sample on the frames between the keys:

    MOTIONFIELD_PYTHON=python MOTIONFIELD_LIBRARY=build/capi/libmotionfield.so.0 \\
      blender -b --factory-startup --python integrations/blender/tests/measure_inbetween.py \\
      [-- [--method M] [--root BONE] [--fps F] [--euler]]

--root sets the Root bone (joint_Root: the add-on's root before it found the
travel), --euler imports with Euler XYZ bones (Blender's interpolation then
interpolates Euler angles, as after Blender's own BVH importer).
"""

import argparse

import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]
import motionfield_blender as addon  # noqa: E402
import walk_session  # noqa: E402
from motionfield_blender import engine  # noqa: E402


def main():
    ap = argparse.ArgumentParser(prog="measure_inbetween.py")
    ap.add_argument("--method", default="")
    ap.add_argument("--root", default="")
    ap.add_argument("--fps", type=float, default=24.0)
    ap.add_argument("--euler", action="store_true")
    a = ap.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    mf = engine.load()
    addon.register()
    obj, motion, keys = walk_session.setup(mf, fps=a.fps, rotation_mode='XYZ' if a.euler else 'QUATERNION')
    between = [f for f in range(keys[0], keys[-1] + 1) if f not in keys]
    blender = walk_session.errors(obj, motion, between)
    s = bpy.context.scene.motionfield
    s.root_bone = a.root
    if a.method:
        s.method = a.method
    t = time.time()
    bpy.ops.motionfield.inbetween('EXEC_DEFAULT')
    took = time.time() - t
    ours = walk_session.errors(obj, motion, between)
    print("root bone: %s; method: %s; %.1f s" % (addon.rig_info.root_name(s, obj), a.method or
                                                  "default (%s)" % mf.default_method(), took))
    print("%-14s %10s %10s" % ("", "joints cm", "feet cm"))
    print("%-14s %10.1f %10.1f" % ("Blender", 100 * blender[0], 100 * blender[1]))
    print("%-14s %10.1f %10.1f" % ("In-between", 100 * ours[0], 100 * ours[1]))
    print("%-14s %10.2f %10.2f" % ("ratio", ours[0] / blender[0], ours[1] / blender[1]))
    addon.unregister()


main()
