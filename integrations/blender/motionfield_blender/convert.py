"""Armature + action <-> motionfield motion, through armature-space matrices.

A motion (the C API's conventions) has Y up, metres, per joint a local
rotation relative to its parent and a constant rest offset in the parent's
frame, and a root translation. Blender has Z up and bones with a rest
orientation of their own (bone.matrix_local). Both sides are compared in the
armature's space, frame by frame, from the evaluated pose:

* joint j's global frame is the pose bone's armature-space rotation G_j
  (pose_bone.matrix, rest orientation included) turned to Y up: C @ G_j;
* its local rotation is G_parent^T @ G_j (C @ G_root for the root);
* its offset is the bone head relative to the parent's head in the parent
  bone's rest frame (constant when non-root bones only rotate);
* the root position is C @ head of the root bone.

Back, forward kinematics gives every bone's armature-space matrix, and the
pose-bone channels follow from Blender's own relation
``pose.matrix = parent.matrix @ (parent.rest^-1 @ rest) @ basis``.
Translation and scale of bones other than the root are not represented (the
motion model has a root translation only).
"""

import numpy as np
from mathutils import Euler, Matrix, Quaternion, Vector

# Blender (x, y, z) with Z up -> motionfield (x, z, -y) with Y up; a rotation.
C3 = Matrix(((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0)))
C3T = C3.transposed()


class RigError(ValueError):
    """The armature cannot be read as a motion skeleton (the message says why)."""


def metres_per_unit(scene, obj):
    """Metres per unit of `obj`'s armature space: the scene's unit scale times
    the object's (mean) world scale, e.g. 0.01 for an FBX import in centimetres
    under an object scaled by 0.01."""
    s = obj.matrix_world.to_scale()
    return (scene.unit_settings.scale_length or 1.0) * (abs(s.x) + abs(s.y) + abs(s.z)) / 3.0


def default_root(arm):
    """The root bone of the armature's biggest tree."""
    roots = [b for b in arm.bones if b.parent is None]
    if not roots:
        raise RigError("the armature has no bones")
    # Several roots (control bones beside the skeleton): the biggest tree.
    return max(roots, key=lambda b: len(b.children_recursive))


class Rig:
    """The bones below (and including) the root bone, as a motion skeleton.

    Attributes: names, parents (indices, -1 for the root), offsets [J, 3]
    metres, rest [J] Matrix (bone.matrix_local), scale (metres per Blender
    unit), root_parent (name of the root bone's parent or None).
    """

    def __init__(self, obj, root_bone="", scale=1.0):
        if obj is None or obj.type != 'ARMATURE':
            raise RigError("the active object is not an armature")
        arm = obj.data
        if root_bone:
            root = arm.bones.get(root_bone)
            if root is None:
                raise RigError("the armature has no bone named %r" % root_bone)
        else:
            root = default_root(arm)
        order = [root]
        i = 0
        while i < len(order):  # breadth first: every parent before its children
            order.extend(sorted(order[i].children, key=lambda b: b.name))
            i += 1
        if len(order) < 2:
            raise RigError("bone %r has no child bones" % root.name)
        index = {b.name: k for k, b in enumerate(order)}
        self.scale = float(scale)
        self.names = [b.name for b in order]
        self.parents = [-1] + [index[b.parent.name] for b in order[1:]]
        self.rest = [b.matrix_local.copy() for b in order]
        self.root_parent = root.parent.name if root.parent else None
        self.parent_rest = root.parent.matrix_local.copy() if root.parent else None
        off = np.zeros((len(order), 3), dtype=np.float64)
        off[0] = C3 @ root.head_local * self.scale
        for k in range(1, len(order)):
            p = self.parents[k]
            d = order[k].head_local - order[p].head_local
            off[k] = (self.rest[p].to_3x3().normalized().transposed() @ d) * self.scale
        self.offsets = off.astype(np.float32)

    def rest_relative(self, k):
        """Blender's relative rest matrix of bone k (k > 0): parent.rest^-1 @ rest."""
        return self.rest[self.parents[k]].inverted() @ self.rest[k]

    def rest_frame_offsets(self):
        """[J, 3] metres: the offsets in frames that are the identity at rest
        (what a BVH file holds: each head relative to its parent's, Y up),
        the root's its rest head."""
        off = np.zeros((len(self.names), 3), dtype=np.float32)
        heads = [r.translation for r in self.rest]
        off[0] = C3 @ heads[0] * self.scale
        for k in range(1, len(self.names)):
            off[k] = C3 @ (heads[k] - heads[self.parents[k]]) * self.scale
        return off


def _rest_axes(rig):
    """Per bone, its rest orientation in motion space (C @ bone.matrix_local)."""
    return [C3 @ r.to_3x3().normalized() for r in rig.rest]


def _globals(parents, local):
    out = []
    for k, p in enumerate(parents):
        out.append(local[k] if p < 0 else out[p] @ local[k])
    return out


def _locals(parents, glob):
    return [g if p < 0 else glob[p].transposed() @ g for g, p in zip(glob, parents)]


def _requaternion(rotations, convert_globals):
    out = np.empty_like(rotations)
    for f in range(rotations.shape[0]):
        local = [Quaternion([float(x) for x in q]).normalized().to_matrix() for q in rotations[f]]
        glob = convert_globals(local)
        for k, m in enumerate(glob):
            out[f, k] = tuple(m.to_quaternion())
    return out


def to_rest_frames(rig, rotations):
    """The rig's rotations (bone frames, as read_frames() reads them) as
    rotations of frames that are the identity at rest (a BVH file's), with
    rest_frame_offsets()."""
    axes = _rest_axes(rig)
    return _requaternion(rotations, lambda local: _locals(
        rig.parents, [g @ a.transposed() for g, a in zip(_globals(rig.parents, local), axes)]))


def from_rest_frames(rig, rotations):
    """The inverse of to_rest_frames(): a BVH file's rotations on the rig's bones."""
    axes = _rest_axes(rig)
    return _requaternion(rotations, lambda local: _locals(
        rig.parents, [g @ a for g, a in zip(_globals(rig.parents, local), axes)]))


def rotation_channel(pose_bone):
    """(data path, component count) of a pose bone's rotation in its mode."""
    mode = pose_bone.rotation_mode
    if mode == 'QUATERNION':
        return "rotation_quaternion", 4
    if mode == 'AXIS_ANGLE':
        return "rotation_axis_angle", 4
    return "rotation_euler", 3


def channel_value(pose_bone, path):
    return tuple(getattr(pose_bone, path))


class Sampled:
    """What read_frames() read: the motion arrays, and per frame the root's
    parent pose and the current channel values of every bone."""

    def __init__(self, frames, rotations, root_positions, parent_poses, channels):
        self.frames = frames
        self.rotations = rotations
        self.root_positions = root_positions
        self.parent_poses = parent_poses
        self.channels = channels  # [frame] {(bone, path): tuple}


def read_frames(scene, obj, rig, frames):
    """Evaluates the scene at each frame and reads the armature as a motion."""
    J = len(rig.names)
    rot = np.zeros((len(frames), J, 4), dtype=np.float32)
    root = np.zeros((len(frames), 3), dtype=np.float32)
    parent_poses, channels = [], []
    keep = scene.frame_current
    try:
        for i, f in enumerate(frames):
            scene.frame_set(int(f))
            pbs = obj.pose.bones
            g = [pbs[n].matrix.to_3x3().normalized() for n in rig.names]
            for k in range(J):
                p = rig.parents[k]
                local = C3 @ g[k] if p < 0 else g[p].transposed() @ g[k]
                rot[i, k] = tuple(local.to_quaternion())
            root[i] = C3 @ pbs[rig.names[0]].head * rig.scale
            parent_poses.append(pbs[rig.root_parent].matrix.copy() if rig.root_parent else None)
            ch = {}
            for k, n in enumerate(rig.names):
                path, _ = rotation_channel(pbs[n])
                ch[(n, path)] = channel_value(pbs[n], path)
                if k == 0:
                    ch[(n, "location")] = channel_value(pbs[n], "location")
            channels.append(ch)
    finally:
        scene.frame_set(keep)
    return Sampled(list(frames), rot, root, parent_poses, channels)


def pose_matrices(rig, rotations, root_positions):
    """Forward kinematics: per frame, every bone's armature-space matrix."""
    out = []
    for f in range(rotations.shape[0]):
        g, h, mats = [None] * len(rig.names), [None] * len(rig.names), []
        for k, p in enumerate(rig.parents):
            local = Quaternion([float(x) for x in rotations[f, k]]).normalized().to_matrix()
            if p < 0:
                g[k] = C3T @ local
                h[k] = C3T @ Vector([float(x) for x in root_positions[f]]) / rig.scale
            else:
                g[k] = g[p] @ local
                h[k] = h[p] + g[p] @ Vector([float(x) for x in rig.offsets[k]]) / rig.scale
            m = g[k].to_4x4()
            m.translation = h[k]
            mats.append(m)
        out.append(mats)
    return out


def basis_matrices(rig, mats, parent_pose=None):
    """One frame's pose-bone basis matrices (the channels' matrix) from
    armature-space matrices; parent_pose: the root bone's parent's pose."""
    out = []
    for k, p in enumerate(rig.parents):
        if p < 0:
            if rig.root_parent is None:
                out.append(rig.rest[0].inverted() @ mats[k])
            else:
                rel = rig.parent_rest.inverted() @ rig.rest[0]
                out.append(rel.inverted() @ parent_pose.inverted() @ mats[k])
        else:
            out.append(rig.rest_relative(k).inverted() @ mats[p].inverted() @ mats[k])
    return out


def channel_from_basis(basis, path, previous):
    """The channel value of `path` for a basis matrix, continuous with the
    previous value of the same channel (quaternion sign, Euler branches)."""
    q = basis.to_quaternion().normalized()
    if path == "rotation_quaternion":
        if previous is not None and sum(a * b for a, b in zip(q, previous)) < 0.0:
            q.negate()
        return tuple(q)
    if path == "rotation_axis_angle":
        axis, angle = q.to_axis_angle()
        return (angle, axis.x, axis.y, axis.z)
    if path == "location":
        return tuple(basis.translation)
    raise ValueError(path)


def euler_from_basis(basis, order, previous):
    q = basis.to_quaternion().normalized()
    if previous is not None:
        return tuple(q.to_euler(order, Euler(previous, order)))
    return tuple(q.to_euler(order))
