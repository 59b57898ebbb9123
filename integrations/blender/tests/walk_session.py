"""An animator's first session on the sample walk, for the tests and for
measure_inbetween.py: the sample imported as Blender's own BVH importer
lays it out (a static `joint_Root` container bone above `Hips`, which carries
the travel), only every 20th frame kept as a key, in a 24 fps scene; and the
error of the armature's pose against the full sample."""

import os

import bpy
from mathutils import Vector

from motionfield_blender import convert, motion_io

SAMPLE = os.path.join(os.environ.get("MF_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..")),
                      "samples", "walk_keyframes.bvh")
FEET = ("Foot_L", "Foot_R", "Toes_L", "Toes_R")


def add_container_root(obj, name="joint_Root"):
    """A static bone at the origin above the armature's root bone, keyed (at
    zero) on every frame the root bone is keyed on, as Blender's BVH importer
    keys a BVH file's 6-channel container joint."""
    root = convert.default_root(obj.data).name
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode='EDIT')
    eb = obj.data.edit_bones
    c = eb.new(name)
    c.head, c.tail = (0.0, 0.0, 0.0), (0.0, 0.0, 0.1)
    eb[root].parent = c
    bpy.ops.object.mode_set(mode='OBJECT')
    fc = obj.animation_data.action.fcurves.find('pose.bones["%s"].location' % root, index=0)
    pb = obj.pose.bones[name]
    pb.rotation_mode = 'XYZ'
    for k in fc.keyframe_points:
        pb.keyframe_insert("location", frame=k.co[0], group=name)
        pb.keyframe_insert("rotation_euler", frame=k.co[0], group=name)


def keep_keys(obj, frames):
    """Deletes every key of the action that is not on one of `frames`."""
    keep = set(frames)
    for fc in obj.animation_data.action.fcurves:
        for k in reversed(list(fc.keyframe_points)):
            if int(round(k.co[0])) not in keep:
                fc.keyframe_points.remove(k, fast=True)
        fc.update()


def setup(mf, fps=24, every=20, container=True, rotation_mode='QUATERNION'):
    """The sample imported into an empty scene at `fps`, keys every `every`
    frames. Returns (armature, the full sample, the key frames)."""
    scene = bpy.context.scene
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    scene.render.fps, scene.render.fps_base = int(fps), 1.0
    obj, motion = motion_io.import_motion(bpy.context, mf, SAMPLE, rotation_mode=rotation_mode)
    scene.frame_start, scene.frame_end = 1, motion.frame_count
    if container:
        add_container_root(obj)
    keys = list(range(1, motion.frame_count + 1, every))
    keep_keys(obj, keys)
    return obj, motion, keys


def errors(obj, motion, frames, first=1, names=None):
    """(mean joint error, mean feet error) in metres of the armature's bone
    heads on `frames` against the motion's joint positions; `names`: the
    bones of the motion's joints (by default the sample's joint names)."""
    scene = bpy.context.scene
    names = list(names or motion.joint_names)
    feet = [names.index(n) for n in FEET if n in names] or [0]
    total = foot = 0.0
    for f in frames:
        scene.frame_set(f)
        for j, n in enumerate(names):
            want = convert.C3T @ Vector([float(x) for x in motion.global_positions[f - first, j]])
            d = (obj.matrix_world @ obj.pose.bones[n].head - want).length
            total += d
            foot += d if j in feet else 0.0
    return total / (len(frames) * len(names)), foot / (len(frames) * len(feet))
