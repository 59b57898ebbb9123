"""Reading keyed frames from an action and writing a motion back as keys."""

import bpy

from . import convert

EPS = 1e-7


def bone_of(data_path):
    """The bone name of a 'pose.bones["NAME"].channel' F-curve path, else None."""
    if not data_path.startswith('pose.bones["'):
        return None
    end = data_path.find('"]', 12)
    return data_path[12:end] if end > 0 else None


def fcurves_of(obj, action=None):
    """The F-curves `obj` plays from `action` (default: its action): the
    action's own on Blender 3.x-4.x, the slot's channel bag on the layered
    actions of Blender versions without Action.fcurves."""
    action = action or obj.animation_data.action
    if hasattr(action, "fcurves"):
        return action.fcurves
    from bpy_extras import anim_utils
    return anim_utils.action_ensure_channelbag_for_slot(action, obj.animation_data.action_slot).fcurves


def _generated_type():
    """Blender's key type for generated keys: 'GENERATED' (Blender 4.2 on),
    else 'BREAKDOWN'."""
    types = bpy.types.Keyframe.bl_rna.properties["type"].enum_items.keys()
    return 'GENERATED' if 'GENERATED' in types else 'BREAKDOWN'


GENERATED_PROP = "motionfield_generated"  # the action's frames the add-on generated


def generated_frames(action):
    return set(int(f) for f in action.get(GENERATED_PROP, []))


def _set_generated_frames(action, frames):
    if frames:
        action[GENERATED_PROP] = sorted(frames)
    elif GENERATED_PROP in action:
        del action[GENERATED_PROP]


def is_generated(key, generated, kind):
    """A key the add-on wrote: on a frame it generated and still of the
    generated type (an animator's re-key there makes it a keyframe again)."""
    return key.type == kind and int(round(key.co[0])) in generated


def keyed_frames(obj, bone_names):
    """Sorted integer frames where an F-curve of one of the bones has a key of
    the animator's (generated keys do not count)."""
    names = set(bone_names)
    generated, kind = generated_frames(obj.animation_data.action), _generated_type()
    frames = set()
    for fc in fcurves_of(obj):
        if bone_of(fc.data_path) in names:
            frames.update(int(round(k.co[0])) for k in fc.keyframe_points if not is_generated(k, generated, kind))
    return sorted(frames)


def animator_keys(obj, bone_names, first, last):
    """{(data path, index): ((frame, value), ...)} of the animator's keys (not
    the generated ones) of the bones' F-curves on frames first..last."""
    names = set(bone_names)
    generated, kind = generated_frames(obj.animation_data.action), _generated_type()
    out = {}
    for fc in fcurves_of(obj):
        if bone_of(fc.data_path) in names:
            out[(fc.data_path, fc.array_index)] = tuple(
                (k.co[0], k.co[1]) for k in fc.keyframe_points
                if first <= k.co[0] <= last and not is_generated(k, generated, kind))
    return out


def clear_generated(obj):
    """Removes the generated keys from the armature's action; returns how many
    frames had some."""
    action = obj.animation_data.action
    generated, kind = generated_frames(action), _generated_type()
    cleared = set()
    for fc in fcurves_of(obj):
        if bone_of(fc.data_path) is None:
            continue
        for k in reversed(list(fc.keyframe_points)):
            if is_generated(k, generated, kind):
                cleared.add(int(round(k.co[0])))
                fc.keyframe_points.remove(k, fast=True)
        fc.update()
    _set_generated_frames(action, set())
    return len(cleared)


def selected_key_frames(obj, bone_names):
    names = set(bone_names)
    frames = set()
    for fc in fcurves_of(obj):
        if bone_of(fc.data_path) in names:
            frames.update(int(round(k.co[0])) for k in fc.keyframe_points if k.select_control_point)
    return sorted(frames)


def channel_paths(obj, rig):
    """[(bone, data path, component count, rotation mode)] the motion drives."""
    out = []
    for k, name in enumerate(rig.names):
        pb = obj.pose.bones[name]
        path, n = convert.rotation_channel(pb)
        out.append((name, path, n, pb.rotation_mode))
        if k == 0:
            out.append((name, "location", 3, None))
    return out


def channel_values(obj, rig, sampled, motion_rot, motion_root, new):
    """{(bone, path): [value per sampled frame]}: the motion's pose on the
    frames in `new`, the current values elsewhere, continuous from frame to
    frame (quaternion signs, Euler branches)."""
    mats = convert.pose_matrices(rig, motion_rot, motion_root)
    chans = channel_paths(obj, rig)
    values = {(b, p): [] for b, p, _, _ in chans}
    for i, f in enumerate(sampled.frames):
        basis = convert.basis_matrices(rig, mats[i], sampled.parent_poses[i]) if f in new else None
        for b, p, _, mode in chans:
            seq = values[(b, p)]
            prev = seq[-1] if seq else None
            if basis is None:
                seq.append(sampled.channels[i][(b, p)])
                continue
            m = basis[rig.names.index(b)]
            if p == "rotation_euler":
                seq.append(convert.euler_from_basis(m, mode, prev))
            else:
                seq.append(convert.channel_from_basis(m, p, prev))
    return values


def _fcurve(fcurves, bone, path, index, create):
    dp = 'pose.bones["%s"].%s' % (bone.replace('"', '\\"'), path)
    fc = fcurves.find(dp, index=index)
    if fc is None and create:
        try:
            fc = fcurves.new(dp, index=index, action_group=bone)
        except TypeError:  # a channel bag's F-curves take no group
            fc = fcurves.new(dp, index=index)
    return fc


def insert_keys(obj, rig, sampled, values, new, keyed):
    """Keys the values on the frames in `new` on the action's F-curves (made
    when missing and the channel changes) as generated keys (replacing the
    generated keys there). Each F-curve written also gets a key with its
    current value on every keyed frame of the range it lacks one on, so that
    the pose on keyed frames stays what it was."""
    fcurves = fcurves_of(obj)
    kind = _generated_type()
    frames = sampled.frames
    written = 0
    for (bone, path), seq in values.items():
        for c in range(len(seq[0])):
            old = [sampled.channels[i][(bone, path)][c] for i in range(len(frames))]
            changed = any(abs(seq[i][c] - old[i]) > EPS for i in range(len(frames)))
            fc = _fcurve(fcurves, bone, path, c, changed)
            if fc is None:
                continue
            have = {int(round(k.co[0])) for k in fc.keyframe_points}
            for i, f in enumerate(frames):
                if f in new:
                    # The type set on the key: insert()'s keyframe_type gives MOVING_HOLD for
                    # 'BREAKDOWN' in Blender 3.4.
                    fc.keyframe_points.insert(f, seq[i][c], options={'FAST'}).type = kind
                    written += 1
                elif f in keyed and f not in have:
                    fc.keyframe_points.insert(f, old[i], options={'FAST'})
            fc.update()
    action = obj.animation_data.action
    _set_generated_frames(action, generated_frames(action) | set(new))
    return written


def motion_channels(obj, rig, mats, parent_pose):
    """{(bone, path): [value per frame]} of the armature-space matrices `mats`
    (pose_matrices()), continuous from frame to frame."""
    chans = channel_paths(obj, rig)
    seqs = {(b, p): [] for b, p, _, _ in chans}
    for mf in mats:
        basis = convert.basis_matrices(rig, mf, parent_pose)
        for b, p, _, mode in chans:
            seq = seqs[(b, p)]
            m = basis[rig.names.index(b)]
            prev = seq[-1] if seq else None
            seq.append(convert.euler_from_basis(m, mode, prev) if p == "rotation_euler"
                       else convert.channel_from_basis(m, p, prev))
    return seqs


def write_channels(obj, action, seqs, first_frame, interpolation):
    """Replaces the keys of the channels in `seqs` in `action` by one key a
    frame from `first_frame` on."""
    fcurves = fcurves_of(obj, action)
    for (b, p), seq in seqs.items():
        for c in range(len(seq[0])):
            fc = _fcurve(fcurves, b, p, c, True)
            fc.keyframe_points.clear()
            fc.keyframe_points.add(len(seq))
            co = []
            for i, v in enumerate(seq):
                co += [float(first_frame + i), float(v[c])]
            fc.keyframe_points.foreach_set("co", co)
            for k in fc.keyframe_points:
                k.interpolation = interpolation
            fc.update()


def new_action_with(obj, rig, motion_rot, motion_root, first_frame, suffix, parent_pose):
    """A copy of the armature's action whose rig channels are replaced by the
    motion from `first_frame` on; assigned to the armature. The old action is
    kept (fake user) so that nothing is lost."""
    old = obj.animation_data.action
    act = old.copy()
    act.name = old.name + suffix
    old.use_fake_user = True
    seqs = motion_channels(obj, rig, convert.pose_matrices(rig, motion_rot, motion_root), parent_pose)
    obj.animation_data.action = act
    write_channels(obj, act, seqs, first_frame, 'LINEAR')
    return act


def mark_generated(obj, action, frames):
    """Makes the keys of the bones' F-curves of `action` on `frames` generated
    keys: their key type, and the action's record of generated frames (which
    then holds exactly `frames`)."""
    frames, kind = set(frames), _generated_type()
    for fc in fcurves_of(obj, action):
        if bone_of(fc.data_path) is None:
            continue
        for k in fc.keyframe_points:
            if int(round(k.co[0])) in frames:
                k.type = kind
    _set_generated_frames(action, frames)


def moving_bones(obj):
    """Names of the bones whose keyed channels change over the action."""
    out = set()
    if obj.animation_data is None or obj.animation_data.action is None:
        return out
    for fc in fcurves_of(obj):
        name = bone_of(fc.data_path)
        if name is None or name in out or len(fc.keyframe_points) < 2:
            continue
        values = [0.0] * (2 * len(fc.keyframe_points))
        fc.keyframe_points.foreach_get("co", values)
        if max(values[1::2]) - min(values[1::2]) > EPS:
            out.add(name)
    return out


def travel_root(obj):
    """The bone that carries the character: from the armature's root bone (of
    the biggest tree) down through static container bones (a BVH import's
    `joint_Root` above `Hips`, Unreal's `root` above `pelvis`) to the first
    bone that moves, following the child with the biggest tree; the armature's
    root bone when nothing below it moves."""
    bone = convert.default_root(obj.data)
    moving = moving_bones(obj)
    while bone.name not in moving and bone.children:
        main = max(bone.children, key=lambda b: (len(b.children_recursive), b.name))
        if not main.children or not any(b.name in moving for b in [main] + list(main.children_recursive)):
            break
        bone = main
    return bone
