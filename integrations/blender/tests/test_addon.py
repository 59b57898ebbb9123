"""Headless test of the motionfield Blender add-on:

    blender -b --factory-startup --python-exit-code 1 --python test_addon.py

Environment (CMake's test sets it): MF_BLENDER_ADDON_DIR (integrations/blender),
MOTIONFIELD_PYTHON (python/), MOTIONFIELD_LIBRARY (libmotionfield.so),
MF_SOURCE_DIR (the checkout, for samples/walk_keyframes.bvh).

Two armatures are built in code from the sample walk: "A" on the model's
joint names with quaternion bones, "B" with opaque bone names (bone_NN, read
through a rig map), Euler bones, an extra unmapped bone and a static "root"
bone above its hips. Every bone has a rest orientation of its own (pointing
at its child, rolled). A keyed cube stands beside them.
"""

import json
import math
import os
import re
import sys
import tempfile
import time

import bpy
from mathutils import Quaternion, Vector

sys.path[:0] = [os.path.dirname(os.path.abspath(__file__)), os.environ["MF_BLENDER_ADDON_DIR"]]
import motionfield_blender as addon  # noqa: E402
from checks import check, finish, log  # noqa: E402
from motionfield_blender import convert, engine  # noqa: E402



def refresh():
    """After undo/redo every ID reference is stale: look the scene up again."""
    global scene, s
    scene = bpy.context.scene
    s = scene.motionfield


mf = engine.load()
scene = bpy.context.scene
scene.render.fps, scene.render.fps_base = 30, 1.0
scene.frame_start, scene.frame_end = 1, 61
for ob in list(bpy.data.objects):
    if ob.name != "Cube":
        bpy.data.objects.remove(ob)

walk = mf.Motion.load_bvh(os.path.join(os.environ["MF_SOURCE_DIR"], "samples", "walk_keyframes.bvh"))
WALK_KEYS = [0, 15, 30, 45, 60]
# A complete walk to key from (the sample's in-between frames are placeholders).
# The methods that refine with the prior are smooth across keys (the
# transformers alone, e.g. "detail", jump by up to 0.6-0.9 m at the keys).
METHOD = "nemf-detail"
BUDGET = 8  # iterations per window (the add-on's "Iterations"): a faster test
full = mf.inbetween(walk, WALK_KEYS, method=METHOD)
NAMES, PARENTS = full.joint_names, [int(p) for p in full.parents]
GROT = []  # [frame][joint] global rotation (motion space)
for f in range(full.frame_count):
    g = []
    for j, p in enumerate(PARENTS):
        q = Quaternion([float(x) for x in full.rotations[f, j]]).to_matrix()
        g.append(q if p < 0 else g[p] @ q)
    GROT.append(g)
GPOS = full.global_positions


def build_armature(name, bone_names, mode, extra_root=False, prop_bone=None, unit=1.0):
    """An armature whose rest pose is the walk's first frame's skeleton at
    identity rotations; bones point at their first child and are rolled.
    unit: metres per armature unit (the object is scaled by it, as FBX
    imports in centimetres are)."""
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    scene.collection.objects.link(obj)
    obj.location = (1.0, -2.0, 0.0)
    obj.rotation_euler = (0.0, 0.0, math.radians(30.0))
    obj.scale = (unit, unit, unit)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode='EDIT')
    heads = []
    for j, p in enumerate(PARENTS):
        h = Vector([float(x) for x in GPOS[0, 0]]) if p < 0 else heads[p] + Vector([float(x) for x in full.offsets[j]])
        heads.append(h)
    eb = []
    for j, p in enumerate(PARENTS):
        b = arm.edit_bones.new(bone_names[j])
        b.head = convert.C3T @ heads[j] / unit
        kids = [k for k, q in enumerate(PARENTS) if q == j]
        d = (convert.C3T @ (heads[kids[0]] - heads[j])) / unit if kids else Vector((0, 0, 0))
        if d.length < 1e-3 / unit:
            d = (b.head - eb[p].head).normalized() * 0.08 / unit if p >= 0 else Vector((0, 0, 0.1 / unit))
        b.tail = b.head + d
        b.roll = 0.37 * j - 1.0
        if p >= 0:
            b.parent = eb[p]
        eb.append(b)
    if extra_root:
        r = arm.edit_bones.new("root")
        r.head, r.tail = (0, 0, 0), (0, 0.3 / unit, 0)
        eb[0].parent = r
    if prop_bone:
        hand = eb[NAMES.index("Hand_R")]
        pb = arm.edit_bones.new(prop_bone)
        pb.head, pb.tail, pb.parent = hand.tail, hand.tail + Vector((0, 0, -0.1 / unit)), hand
    bpy.ops.object.mode_set(mode='OBJECT')
    obj.animation_data_create()
    obj.animation_data.action = bpy.data.actions.new(name + "_action")
    for pbone in obj.pose.bones:
        pbone.rotation_mode = mode
    return obj


_last_quaternion = {}


def key_pose(obj, bone_names, scene_frame, motion_frame):
    """Poses the armature as the walk's frame (pose_bone.matrix, Blender's own
    conversion) and keys the rotation of every mapped bone and the hips' location."""
    scene.frame_set(scene_frame)
    for j, n in enumerate(bone_names):
        pb = obj.pose.bones[n]
        rest = obj.data.bones[n].matrix_local.to_3x3()
        rot = convert.C3T @ GROT[motion_frame][j] @ convert.C3 @ rest
        m = rot.to_4x4()
        m.translation = convert.C3T @ Vector([float(x) for x in GPOS[motion_frame, j]]) / obj.scale.x
        pb.matrix = m
        bpy.context.view_layer.update()
    for j, n in enumerate(bone_names):
        pb = obj.pose.bones[n]
        last = _last_quaternion.get((obj.name, n))
        if pb.rotation_mode == 'QUATERNION':  # keys as an animator's: no sign flips
            if last is not None and pb.rotation_quaternion.dot(last) < 0.0:
                pb.rotation_quaternion.negate()
            _last_quaternion[(obj.name, n)] = pb.rotation_quaternion.copy()
        pb.keyframe_insert(convert.rotation_channel(pb)[0], frame=scene_frame, group=n)
        if j == 0:
            pb.keyframe_insert("location", frame=scene_frame, group=n)


def fcurve_snapshot(action):
    return {(fc.data_path, fc.array_index): [tuple(k.co) for k in fc.keyframe_points] for fc in action.fcurves}


def poses(obj, frames):
    out = {}
    for f in frames:
        scene.frame_set(f)
        out[f] = {pb.name: pb.matrix.copy() for pb in obj.pose.bones}
    return out


def mat_diff(a, b, unit=1.0):
    """Largest difference of two bone matrices: rotation entries, and the
    translation in metres (`unit`: metres per armature unit)."""
    return max(abs(a[i][j] - b[i][j]) * (unit if j == 3 else 1.0) for i in range(4) for j in range(4))


def cube_state():
    """What an operator on the active armature must not change: the cube, the
    other armatures' actions, the set of objects."""
    cube = bpy.data.objects["Cube"]
    scene.frame_set(10)
    active = bpy.context.view_layer.objects.active
    others = {o.name: fcurve_snapshot(o.animation_data.action) for o in bpy.data.objects
              if o.type == 'ARMATURE' and o != active and o.animation_data and o.animation_data.action}
    return (fcurve_snapshot(cube.animation_data.action), [tuple(v) for v in cube.matrix_world],
            sorted(o.name for o in bpy.data.objects), others)


def operator(name):
    """Runs bpy.ops.motionfield.<name>() as the UI would from a script (EXEC)."""
    return getattr(bpy.ops.motionfield, name)('EXEC_DEFAULT', True)  # True: undo push as from the UI


def heads_of(obj, frames, names):
    out = {}
    for f in frames:
        scene.frame_set(f)
        out[f] = [obj.pose.bones[n].head.copy() for n in names]
    return out


def max_jump(obj, names, f0, f1):
    """The largest distance a bone head moves from frame f0 to f1, metres."""
    h = heads_of(obj, [f0, f1], names)
    return max((a - b).length for a, b in zip(h[f0], h[f1])) * obj.scale.x


def library_result(obj, settings_root, frames, call):
    """What the library gives for the armature's current frames: the expected
    result of the operator (equal seeds give equal results)."""
    rig = convert.Rig(obj, settings_root, convert.metres_per_unit(scene, obj))
    sampled = convert.read_frames(scene, obj, rig, frames)
    motion = mf.Motion.from_arrays(sampled.rotations, sampled.root_positions, 30.0, joint_names=rig.names,
                                   parents=rig.parents, offsets=rig.offsets)
    return rig, call(motion)


def expect_heads(obj, rig, result, frames, first, what):
    """The armature's bone heads on `frames` are the result's joint positions."""
    worst = 0.0
    for f in frames:
        scene.frame_set(f)
        for j, n in enumerate(rig.names):
            want = convert.C3T @ Vector([float(x) for x in result.global_positions[f - first, j]]) / rig.scale
            worst = max(worst, (obj.pose.bones[n].head - want).length * rig.scale)
    check(worst < 1e-4, "%s: heads differ from the library's result by %g m" % (what, worst))


# ------------------------------------------------------------------ scene
addon.register()
cube = bpy.data.objects["Cube"]
cube.keyframe_insert("location", frame=1)
cube.location.x += 2.0
cube.keyframe_insert("location", frame=40)

A = build_armature("A", NAMES, 'QUATERNION')
for k in WALK_KEYS:
    key_pose(A, NAMES, 1 + k, k)
# The head is not keyed on frame 31 (keyed for the others): its pose there is
# interpolated and must stay so.
for c in range(4):
    fc = A.animation_data.action.fcurves.find('pose.bones["Head"].rotation_quaternion', index=c)
    fc.keyframe_points.remove(next(k for k in fc.keyframe_points if int(k.co[0]) == 31))
B_NAMES = ["bone_%02d" % j for j in range(len(NAMES))]
B = build_armature("B", B_NAMES, 'XYZ', extra_root=True, prop_bone="bone_prop", unit=0.01)  # centimetres
B_KEYED = list(range(1, 21)) + list(range(41, 62))
for f in B_KEYED:
    key_pose(B, B_NAMES, f, f - 1)
rig_map = dict(zip(B_NAMES, NAMES))
rig_map["bone_prop"] = None
rig_map_path = os.path.join(tempfile.mkdtemp(), "rig_b.json")
with open(rig_map_path, "w") as fh:
    json.dump(rig_map, fh)
log("scene built")

# ------------------------------------------------------------------ round trip
for obj, root in ((A, ""), (B, "bone_00")):
    rig = convert.Rig(obj, root, convert.metres_per_unit(scene, obj))
    frames = list(range(1, 62, 3))
    sampled = convert.read_frames(scene, obj, rig, frames)
    motion = mf.Motion.from_arrays(sampled.rotations, sampled.root_positions, 30.0, joint_names=rig.names,
                                   parents=rig.parents, offsets=rig.offsets)
    mats = convert.pose_matrices(rig, motion.rotations, motion.root_positions)
    worst_m = worst_b = 0.0
    for i, f in enumerate(frames):
        scene.frame_set(f)
        basis = convert.basis_matrices(rig, mats[i], sampled.parent_poses[i])
        for j, n in enumerate(rig.names):
            pb = obj.pose.bones[n]
            worst_m = max(worst_m, mat_diff(mats[i][j], pb.matrix, rig.scale))
            worst_b = max(worst_b, mat_diff(basis[j], pb.matrix_basis, rig.scale))
    check(worst_m < 1e-4, "round trip %s: armature-space matrices differ by %g" % (obj.name, worst_m))
    check(worst_b < 1e-4, "round trip %s: basis matrices differ by %g" % (obj.name, worst_b))
    log("round trip", obj.name, worst_m, worst_b)
check(mf.describe_rig(motion, rig_map=rig_map_path)["map"]["bone_05"] == NAMES[5], "rig map of B")

# ------------------------------------------------------------------ in-between (A)
s = scene.motionfield
s.method, s.root_bone, s.range_mode, s.seed, s.max_iterations = METHOD, "", 'SCENE', 3, BUDGET
bpy.context.view_layer.objects.active = A
keys_a = [1 + k for k in WALK_KEYS]
before_keys = fcurve_snapshot(A.animation_data.action)
before_pose = poses(A, keys_a)
other = cube_state()
rig_a, expected = library_result(A, "", list(range(1, 62)),
                                 lambda m: mf.inbetween(m, WALK_KEYS, method=METHOD, seed=3,
                                                       max_iterations=BUDGET))
bpy.ops.ed.undo_push(message="before in-between")
check(operator("inbetween") == {'FINISHED'}, "in-between finished")
A = bpy.data.objects["A"]
after_keys = fcurve_snapshot(A.animation_data.action)
for key, pts in before_keys.items():
    now = dict(after_keys.get(key, []))
    check(all(abs(now.get(f, math.inf) - v) < 1e-6 for f, v in pts), "in-between kept the keys of %s" % (key,))
after_pose = poses(A, keys_a)
worst = max(mat_diff(before_pose[f][n], after_pose[f][n]) for f in keys_a for n in NAMES)
check(worst < 1e-5, "in-between: pose on keyed frames changed by %g" % worst)
hips_keys = sorted(int(f) for f, _ in after_keys[('pose.bones["Hips"].rotation_quaternion', 0)])
check(hips_keys == list(range(1, 62)), "in-between keyed every frame 1..61: %s" % hips_keys)
check(all(math.isfinite(v) for pts in after_keys.values() for _, v in pts), "in-between: finite keys")
for n in NAMES:  # quaternion keys keep their sign from frame to frame
    q = [[v for _, v in after_keys[('pose.bones["%s"].rotation_quaternion' % n, c)]] for c in range(4)]
    flips = [f for f in range(len(q[0]) - 1) if sum(q[c][f] * q[c][f + 1] for c in range(4)) < 0.0]
    check(not flips, "in-between: quaternion sign flips of %s after keys %s" % (n, flips))
new_a = [f for f in range(1, 62) if f not in keys_a]
expect_heads(A, rig_a, expected, new_a, 1, "in-between")
check(max_jump(A, NAMES, 2, 14) > 0.05, "in-between: the new frames move")
# A conversion error (frames, axes, rest orientations) shows as jumps of 0.5 m
# and more next to the keys; the walk's fastest joint moves < 0.2 m a frame.
jump = max(max_jump(A, NAMES, f, f + 1) for f in range(1, 61))
check(jump < 0.25, "in-between: no jump between frames (%.3f m)" % jump)
check(cube_state() == other, "in-between left the cube and B alone")
# One undo step: undo gives the keys before, redo the result.
bpy.ops.ed.undo()
refresh()
A = bpy.data.objects["A"]
check(fcurve_snapshot(A.animation_data.action) == before_keys, "undo restores A's action")
bpy.ops.ed.redo()
refresh()
A = bpy.data.objects["A"]
check(fcurve_snapshot(A.animation_data.action) == after_keys, "redo gives the in-between again")
log("in-between")

# ------------------------------------------------------------------ fill gap (B, rig map, Euler)
s.root_bone, s.rig_map, s.method = "bone_00", rig_map_path, METHOD
bpy.context.view_layer.objects.active = B = bpy.data.objects["B"]
scene.frame_set(30)
before_keys = fcurve_snapshot(B.animation_data.action)
before_pose = poses(B, B_KEYED)
other = cube_state()
rig_b, expected = library_result(B, "bone_00", list(range(1, 62)),
                                 lambda m: mf.fill(m, 20, 40, method=METHOD, seed=3, rig_map=rig_map_path,
                                                   max_iterations=BUDGET))
scene.frame_set(30)
bpy.ops.ed.undo_push(message="before fill")
check(operator("fill") == {'FINISHED'}, "fill finished")
B = bpy.data.objects["B"]
after_keys = fcurve_snapshot(B.animation_data.action)
for key, pts in before_keys.items():
    now = dict(after_keys.get(key, []))
    check(all(abs(now.get(f, math.inf) - v) < 1e-6 for f, v in pts), "fill kept the keys of %s" % (key,))
after_pose = poses(B, B_KEYED)
worst = max(mat_diff(before_pose[f][n], after_pose[f][n], B.scale.x) for f in B_KEYED for n in before_pose[f])
check(worst < 1e-5, "fill: pose on keyed frames changed by %g" % worst)
euler = sorted(int(f) for f, _ in after_keys[('pose.bones["bone_05"].rotation_euler', 0)])
check(euler == list(range(1, 62)), "fill keyed frames 21..40 on the Euler curves")
check(not any(dp.startswith('pose.bones["root"]') for dp, _ in after_keys), "fill left the root bone alone")
expect_heads(B, rig_b, expected, list(range(21, 41)), 1, "fill")
check(max_jump(B, B_NAMES, 22, 39) > 0.05, "fill: the new frames move")
jump = max(max_jump(B, B_NAMES, f, f + 1) for f in range(19, 42))
check(jump < 0.25, "fill: no jump in and around the gap (%.3f m)" % jump)
check(cube_state() == other, "fill left the cube and A alone")
bpy.ops.ed.undo()
refresh()
B = bpy.data.objects["B"]
check(fcurve_snapshot(B.animation_data.action) == before_keys, "undo restores B's action")
bpy.ops.ed.redo()
refresh()
log("fill")

# ------------------------------------------------------------------ resample (B: 61 frames at 60 fps -> 31 at 30)
B = bpy.data.objects["B"]
bpy.context.view_layer.objects.active = B
s.resample_method, s.source_fps = "interp", 60.0
old_action = B.animation_data.action.name
before_keys = fcurve_snapshot(B.animation_data.action)
before_pose = poses(B, list(range(1, 62, 2)))
other = cube_state()
bpy.ops.ed.undo_push(message="before resample")
check(operator("resample") == {'FINISHED'}, "resample finished")
B = bpy.data.objects["B"]
act = B.animation_data.action
check(act.name != old_action, "resample made a new action")
check(fcurve_snapshot(bpy.data.actions[old_action]) == before_keys, "resample left the old action alone")
check(bpy.data.actions[old_action].use_fake_user, "the old action is kept")
hips = sorted(int(f) for f, _ in fcurve_snapshot(act)[('pose.bones["bone_00"].location', 0)])
check(hips == list(range(1, 32)), "resample: 31 frames at 30 fps: %s" % hips[:3])
after_pose = poses(B, list(range(1, 32)))
worst = max(mat_diff(before_pose[1 + 2 * k][n], after_pose[1 + k][n], B.scale.x) for k in range(31) for n in B_NAMES)
check(worst < 1e-4, "resample (interp): frame k is the source's frame 2k (%g)" % worst)
check(cube_state() == other, "resample left the cube and A alone")
bpy.ops.ed.undo()
refresh()
B = bpy.data.objects["B"]
check(B.animation_data.action.name == old_action, "undo gives B its action back")
log("resample")

# ------------------------------------------------------------------ follow path (A)
A = bpy.data.objects["A"]
bpy.context.view_layer.objects.active = A
s.root_bone, s.rig_map, s.path_method = "", "", "nemf"
curve_data = bpy.data.curves.new("path", 'CURVE')
curve_data.dimensions = '3D'
spline = curve_data.splines.new('POLY')
start = A.matrix_world @ A.pose.bones["Hips"].head
pts = [start, start + Vector((0.6, 0.8, 0.0)), start + Vector((1.5, 1.2, 0.0))]
spline.points.add(len(pts) - 1)
for p, v in zip(spline.points, pts):
    p.co = (v.x, v.y, 0.0, 1.0)
curve = bpy.data.objects.new("path", curve_data)
scene.collection.objects.link(curve)
s.path_object = curve
check(operator("follow_path") == {'FINISHED'}, "follow path finished")
act = A.animation_data.action
frames = sorted(int(f) for f, _ in fcurve_snapshot(act)[('pose.bones["Hips"].location', 0)])
check(len(frames) >= 2 and all(math.isfinite(v) for pts_ in fcurve_snapshot(act).values() for _, v in pts_),
      "follow path: finite frames")
scene.frame_set(frames[0])
first = A.matrix_world @ A.pose.bones["Hips"].head
check(abs(first.x - start.x) < 1e-3 and abs(first.y - start.y) < 1e-3,
      "follow path starts at the path's first point: %s vs %s" % (tuple(first), tuple(start)))
check(max_jump(A, NAMES, frames[0], frames[-1]) > 0.05, "follow path: the new frames move")
log("follow path", len(frames), "frames")

# ------------------------------------------------------------------ ranges (C: preview range, selected keys)
C = build_armature("C", NAMES, 'QUATERNION')
for k in WALK_KEYS:
    key_pose(C, NAMES, 1 + k, k)
bpy.context.view_layer.objects.active = C
s.method, s.range_mode = "interp", 'PREVIEW'
scene.use_preview_range, scene.frame_preview_start, scene.frame_preview_end = True, 10, 35
check(operator("inbetween") == {'FINISHED'}, "in-between in the preview range finished")


def hips_frames(obj):
    fc = obj.animation_data.action.fcurves.find('pose.bones["Hips"].rotation_quaternion', index=0)
    return sorted(int(k.co[0]) for k in fc.keyframe_points)


check(hips_frames(C) == [1] + list(range(16, 32)) + [46, 61], "preview range 10..35: frames 17..30 only: %s"
      % hips_frames(C))
scene.use_preview_range = False
s.range_mode = 'SELECTED'
for fc in C.animation_data.action.fcurves:
    for k in fc.keyframe_points:
        k.select_control_point = int(k.co[0]) in (46, 61)
check(operator("inbetween") == {'FINISHED'}, "in-between of the selected keys finished")
check(hips_frames(C) == [1] + list(range(16, 32)) + list(range(46, 62)), "selected keys 46, 61: frames 47..60 only")
s.range_mode = 'SCENE'
log("ranges")

# ------------------------------------------------------------------ errors, progress, cancel
E = build_armature("E", NAMES, 'QUATERNION')
key_pose(E, NAMES, 1, 0)
bpy.context.view_layer.objects.active = E
try:
    operator("inbetween")
    check(False, "in-between on one keyed frame must fail")
except RuntimeError as e:
    check("fewer than two keyed frames" in str(e), "one keyed frame: %s" % e)
bpy.context.view_layer.objects.active = bpy.data.objects["A"]
s.path_object = None
try:
    operator("follow_path")
    check(False, "follow path without a curve must fail")
except RuntimeError as e:
    check("curve" in str(e), "no curve: %s" % e)

seen = []
job = engine.Job(lambda progress, cancel: mf.inbetween(full, WALK_KEYS, method="nemf", progress=progress,
                                                        cancel=cancel))
job.run_inline(lambda p: seen.append(p) or len(seen) >= 2)
check(isinstance(job.error, mf.CancelledError), "progress callback cancels: %r" % job.error)
check(len(seen) >= 2, "progress reported")
job = engine.Job(lambda progress, cancel: mf.inbetween(full, WALK_KEYS, method="nemf", progress=progress,
                                                        cancel=cancel))
job.start()
while job.progress[:2] == (0, 0) and not job.done:
    time.sleep(0.01)
job.cancel()
job.join()
check(isinstance(job.error, mf.CancelledError), "cancel token (Esc) cancels the thread: %r" % job.error)

# The interactive path (invoke -> modal on a timer) needs a window, which
# background mode has not: its modal() runs here on stand-ins of the window
# manager, the workspace and the events.
class _Stub:
    def __init__(self):
        self.calls = []

    def __getattr__(self, name):
        return lambda *a: self.calls.append((name,) + a)


class _Area:
    def __init__(self, kind):
        self.type, self.tagged = kind, 0

    def tag_redraw(self):
        self.tagged += 1


class _Event:
    def __init__(self, kind):
        self.type = kind


def run_modal(press_esc):
    op = type("Op", (addon._TaskOperator,), {"bl_label": "In-between"})()
    op.mf, op._timer, reports = mf, None, []
    op.method_label, op._t0 = "nemf", time.time()  # what _start() and task_kwargs() set
    op.report = lambda kind, message: reports.append(message)
    op._finish = lambda context, result: "%d frames" % result.frame_count
    op._job = engine.Job(lambda progress, cancel: mf.inbetween(full, WALK_KEYS, method="nemf", progress=progress,
                                                                cancel=cancel, max_iterations=BUDGET))
    wm = _Stub()
    wm.windows = [type("Window", (), {"screen": type("Screen", (), {"areas": [_Area('DOPESHEET_EDITOR'),
                                                                             _Area('PROPERTIES')]})()})()]
    ctx = type("Ctx", (), {"window_manager": wm, "workspace": _Stub()})()
    op._job.start()
    state, deadline = {'RUNNING_MODAL'}, time.time() + 60
    while state == {'RUNNING_MODAL'} and time.time() < deadline:
        if press_esc and op._job.progress[:2] != (0, 0):
            op.modal(ctx, _Event('ESC'))
            press_esc = False
        state = op.modal(ctx, _Event('TIMER'))
        time.sleep(0.01)
    return state, reports, ctx


state, reports, ctx = run_modal(press_esc=False)
check(state == {'FINISHED'} and len(reports) == 1 and re.fullmatch(r"motionfield: 61 frames with nemf in [0-9.]+ s",
                                                                    reports[0]), "modal run: %s %s" % (state, reports))
areas = ctx.window_manager.windows[0].screen.areas
check(areas[0].tagged and not areas[1].tagged, "modal run redraws the Dope Sheet (only the animation editors)")
check(any(c[0] == "progress_update" for c in ctx.window_manager.calls), "modal run shows progress")
check(("status_text_set", None) in ctx.workspace.calls, "modal run clears the status text")
state, reports, ctx = run_modal(press_esc=True)
check(state == {'CANCELLED'} and any("cancelled" in r for r in reports), "Esc cancels: %s %s" % (state, reports))
check(ctx.window_manager.windows[0].screen.areas[0].tagged, "a cancelled run redraws too")

addon.unregister()
finish()
