"""Motion files <-> armature and action, through the library's readers and
writers (no dependence on Blender's own BVH importer, which fails on Python
3.11: ``ValueError: invalid mode: 'rU'`` in Blender 3.4).

An imported armature has one bone per joint, in metres, Z up: each bone
points at its child (at the mean of its children's heads when it has
several), and its action has a rotation key per frame on every bone and a
location key per frame on the root bone.
"""

import os

import bpy
from mathutils import Vector

from . import animation, convert

MIN_BONE = 0.02  # metres: a bone shorter than this points up instead
FPS_PROP = "motionfield_fps"  # an imported action's frame rate (its file's)


def _heads(motion):
    """Rest heads [J] in Blender space (metres), the root's at its offset."""
    heads = []
    for j, p in enumerate(motion.parents):
        off = convert.C3T @ Vector([float(x) for x in motion.offsets[j]])
        heads.append(off if p < 0 else heads[p] + off)
    return heads


def _tail(head, child_heads, along):
    if child_heads:
        tip = sum(child_heads, Vector()) / len(child_heads)
        if (tip - head).length >= MIN_BONE:
            return tip
    if along.length >= MIN_BONE:
        return head + along * 0.5
    return head + Vector((0.0, 0.0, 0.1))


def build_armature(context, motion, name):
    """A new armature object (linked to the scene's active collection, made
    active) with the motion's skeleton in its rest pose."""
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    context.collection.objects.link(obj)
    context.view_layer.objects.active = obj
    heads = _heads(motion)
    parents = [int(p) for p in motion.parents]
    bpy.ops.object.mode_set(mode='EDIT')
    try:
        bones = []
        for j, p in enumerate(parents):
            b = arm.edit_bones.new(motion.joint_names[j])
            kids = [heads[k] for k, q in enumerate(parents) if q == j]
            b.head = heads[j]
            b.tail = _tail(heads[j], kids, heads[j] - heads[p] if p >= 0 else Vector())
            b.roll = 0.0
            if p >= 0:
                b.parent = bones[p]
                b.use_connect = False
            bones.append(b)
    finally:
        bpy.ops.object.mode_set(mode='OBJECT')
    return obj


def import_motion(context, mf, path, units="auto", rotation_mode='QUATERNION'):
    """Reads `path` (BVH, glTF 2.0 or FBX; `units` applies to BVH) with the
    library (`mf`: the motionfield package) and builds an armature and its
    action, keyed from the scene's start frame. Returns (armature object, motion)."""
    is_bvh = os.path.splitext(path)[1].lower() == ".bvh"
    motion = mf.Motion.load(path, units=units if is_bvh else None)
    name = os.path.splitext(os.path.basename(path))[0]
    obj = build_armature(context, motion, name)
    for pb in obj.pose.bones:
        pb.rotation_mode = rotation_mode
    rig = convert.Rig(obj, motion.joint_names[0], 1.0)
    order = [motion.joint_names.index(n) for n in rig.names]  # the rig's breadth-first order
    rotations = convert.from_rest_frames(rig, motion.rotations[:, order])
    mats = convert.pose_matrices(rig, rotations, motion.root_positions)
    obj.animation_data_create()
    action = bpy.data.actions.new(name)
    action[FPS_PROP] = float(motion.fps)
    obj.animation_data.action = action
    seqs = animation.motion_channels(obj, rig, mats, None)
    animation.write_channels(obj, action, seqs, context.scene.frame_start, 'BEZIER')
    return obj, motion


def export_motion(context, mf, obj, root_bone, path, frames, fps):
    """Writes the armature's pose on `frames` as a BVH file (metres, a rest
    pose of identity rotations: the armature's own rest pose)."""
    rig = convert.Rig(obj, root_bone, convert.metres_per_unit(context.scene, obj))
    sampled = convert.read_frames(context.scene, obj, rig, frames)
    motion = mf.Motion.from_arrays(convert.to_rest_frames(rig, sampled.rotations), sampled.root_positions, fps,
                                   joint_names=rig.names, parents=rig.parents, offsets=rig.rest_frame_offsets())
    motion.save_bvh(path)
    return motion

