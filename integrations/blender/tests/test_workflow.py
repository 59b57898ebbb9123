"""Headless test of an animator's session with the add-on (walk_session.py):

    blender -b --factory-startup --python-exit-code 1 --python test_workflow.py

Environment as test_addon.py's (CMake's test sets it).
"""

import glob
import os
import sys
import tempfile

import bpy
from mathutils import Quaternion

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.environ.get("MF_BLENDER_ADDON_DIR", os.path.dirname(HERE))]
import motionfield_blender as addon  # noqa: E402
import walk_session  # noqa: E402
from checks import check, finish, log  # noqa: E402
from motionfield_blender import animation, engine, rig_info  # noqa: E402



def snapshot(action, bone):
    prefix = 'pose.bones["%s"]' % bone
    return {(fc.data_path, fc.array_index): [tuple(k.co) for k in fc.keyframe_points]
            for fc in action.fcurves if fc.data_path.startswith(prefix)}


def key_frames(obj, path):
    fc = obj.animation_data.action.fcurves.find(path, index=0)
    return sorted(int(round(k.co[0])) for k in fc.keyframe_points)


mf = engine.load()
addon.register()
s = bpy.context.scene.motionfield

# ------------------------------------------------------------------ the root (static container above Hips)
obj, motion, keys = walk_session.setup(mf)
check(keys == [1, 21, 41, 61], "keys every 20 frames: %s" % keys)
bpy.ops.object.mode_set(mode='EDIT')  # Unreal-like: IK bones beside the skeleton under the container
ik = obj.data.edit_bones.new("ik_foot_root")
ik.head, ik.tail, ik.parent = (0.0, 0.0, 0.0), (0.0, 0.1, 0.0), obj.data.edit_bones["joint_Root"]
leaf = obj.data.edit_bones.new("ik_foot_l")
leaf.head, leaf.tail, leaf.parent = (0.1, 0.0, 0.0), (0.1, 0.1, 0.0), ik
bpy.ops.object.mode_set(mode='OBJECT')
check("Hips" in animation.moving_bones(obj) and "joint_Root" not in animation.moving_bones(obj),
      "moving bones: %s" % sorted(animation.moving_bones(obj))[:4])
check(animation.travel_root(obj).name == "Hips", "the travel is on Hips: %s" % animation.travel_root(obj).name)
check(rig_info.root_name(s, obj) == "Hips", "the default root is the found one")
model = engine.model()
d, error = rig_info.describe(mf, obj, "Hips", 1.0, "", model)
check(error is None and len(d["map"]) == 21, "the rig maps onto the model's 21 joints: %s" % error)
check(rig_info.summary(d).startswith("21 of 21 model joints mapped (21 by name"), rig_info.summary(d) if d else "")
bpy.ops.motionfield.set_root(bone="joint_Root")
check(rig_info.root_name(s, obj) == "joint_Root", "one-click override")
bpy.ops.motionfield.set_root(bone="")
check(rig_info.root_name(s, obj) == "Hips", "back to the found root")

between = [f for f in range(1, 62) if f not in keys]
blender = walk_session.errors(obj, motion, between)
container = snapshot(obj.animation_data.action, "joint_Root")
check(bpy.ops.motionfield.inbetween('EXEC_DEFAULT') == {'FINISHED'}, "in-between finished")
ours = walk_session.errors(obj, motion, between)
log("blender %.3f %.3f m, in-between %.3f %.3f m" % (blender + ours))
check(snapshot(obj.animation_data.action, "joint_Root") == container, "the container root keeps its keys")
check(key_frames(obj, 'pose.bones["Hips"].location') == list(range(1, 62)), "the travel is keyed on Hips")
check(ours[1] < blender[1], "feet closer to the sample than Blender's interpolation: %.3f vs %.3f m"
      % (ours[1], blender[1]))
check(ours[0] < blender[0], "joints closer than Blender's interpolation: %.3f vs %.3f m" % (ours[0], blender[0]))
log("root")

# ------------------------------------------------------------------ generated keys apart from the animator's
kind = animation._generated_type()
action = obj.animation_data.action
types = {}
for fc in action.fcurves:
    if animation.bone_of(fc.data_path) in ("Hips", "UpperLeg_L"):
        for k in fc.keyframe_points:
            types.setdefault(k.type, set()).add(int(round(k.co[0])))
check(types == {'KEYFRAME': set(keys), kind: set(between)}, "generated keys are %s, the animator's keyframes: %s"
      % (kind, {t: sorted(f)[:3] for t, f in types.items()}))
check(animation.generated_frames(action) == set(between), "the action records the generated frames")
check(animation.keyed_frames(obj, list(motion.joint_names)) == keys, "generated keys are not the animator's")
scene = bpy.context.scene
scene.frame_set(21)  # the animator tweaks the key on frame 21: raises the left arm
arm = obj.pose.bones["UpperArm_L"]
arm.rotation_quaternion = arm.rotation_quaternion @ Quaternion((0.0, 1.0, 0.0), 0.6)
arm.keyframe_insert("rotation_quaternion", frame=21)
before = {(fc.data_path, fc.array_index): {int(round(k.co[0])): k.co[1] for k in fc.keyframe_points}
          for fc in action.fcurves}
check(bpy.ops.motionfield.inbetween('EXEC_DEFAULT') == {'FINISHED'}, "regenerate after a tweak finished")
after = {(fc.data_path, fc.array_index): {int(round(k.co[0])): k.co[1] for k in fc.keyframe_points}
         for fc in action.fcurves}
check(after.keys() == before.keys() and all(after[c].keys() == before[c].keys() for c in before),
      "regenerating keys the same frames")
check(all(abs(after[c][f] - before[c][f]) < 1e-6 for c in before for f in keys if f in before[c]),
      "regenerating keeps the animator's keys")
moved = [f for f in between if any(abs(after[c][f] - before[c][f]) > 1e-3 for c in before if f in before[c])]
check(set(range(12, 31)) - {21} <= set(moved), "regenerating changes the generated frames around the tweak: %s" % moved)
check(bpy.ops.motionfield.clear_generated('EXEC_DEFAULT') == {'FINISHED'}, "clear generated")
left = {int(round(k.co[0])) for fc in action.fcurves for k in fc.keyframe_points}
check(left == set(keys), "clear generated leaves the animator's keys: %s" % sorted(left))
check(not animation.generated_frames(action), "clear generated forgets the generated frames")
log("generated keys")

# ------------------------------------------------------------------ alternatives to cycle through
from motionfield_blender import alternatives  # noqa: E402


def generated_values(action, frames):
    return {(fc.data_path, fc.array_index, int(round(k.co[0]))): k.co[1] for fc in action.fcurves
            for k in fc.keyframe_points if int(round(k.co[0])) in frames}


obj, motion, keys = walk_session.setup(mf)
action = obj.animation_data.action
s.alternatives, s.max_iterations = 2, 30
check(alternatives.current(obj) is None, "no alternatives before a run")
check(bpy.ops.motionfield.inbetween('EXEC_DEFAULT') == {'FINISHED'}, "in-between with alternatives finished")
check(alternatives.current(obj) == (0, 3), "the method's answer and 2 alternatives: %s" % (alternatives.current(obj),))
first, animator = generated_values(action, set(between)), generated_values(action, set(keys))
check(bpy.ops.motionfield.alternative(step=1) == {'FINISHED'} and alternatives.current(obj) == (1, 3), "next")
second = generated_values(action, set(between))
check(second.keys() == first.keys(), "an alternative keys the same generated frames")
check(max(abs(second[k] - first[k]) for k in first) > 1e-3, "the alternative is another motion")
check(generated_values(action, set(keys)) == animator, "cycling keeps the animator's keys")
check(all(k.type == kind for fc in action.fcurves for k in fc.keyframe_points if int(round(k.co[0])) in between),
      "alternatives are generated keys too")
bpy.ops.motionfield.alternative(step=1)
bpy.ops.motionfield.alternative(step=1)
back = generated_values(action, set(between))
check(alternatives.current(obj) == (0, 3) and max(abs(back[k] - first[k]) for k in first) < 1e-6,
      "three steps come back to the method's answer")
bpy.ops.motionfield.alternative(step=-1)
check(alternatives.current(obj) == (2, 3), "previous from the first is the last")
scene.frame_set(21)
arm = obj.pose.bones["UpperArm_L"]
arm.rotation_quaternion = arm.rotation_quaternion @ Quaternion((0.0, 1.0, 0.0), 0.6)
arm.keyframe_insert("rotation_quaternion", frame=21)  # a key edited by the animator ...
try:
    edited = bpy.ops.motionfield.alternative(step=1)
except RuntimeError as e:  # the operator's error report
    edited = str(e)
check("keys changed" in str(edited) and alternatives.current(obj) is None, "... makes the alternatives out of date: %s"
      % edited)
check(not addon.MOTIONFIELD_OT_alternative.poll(bpy.context), "and the buttons greyed")
s.alternatives, s.max_iterations = 0, 0
log("alternatives")

# ------------------------------------------------------------------ resample moves the found root with the pose
obj, motion, keys = walk_session.setup(mf)
s.resample_method = "interp"
check(bpy.ops.motionfield.resample('EXEC_DEFAULT') == {'FINISHED'}, "resample finished")
count = mf.resample_frame_count(61, 30.0, 24.0)[0]
ends = {p: key_frames(obj, 'pose.bones["Hips"].%s' % p)[-1] for p in ("location", "rotation_quaternion")}
check(ends == {"location": count, "rotation_quaternion": count},
      "the travel ends with the pose at frame %d: %s" % (count, ends))
s.resample_method = "DEFAULT"
log("resample")

# ------------------------------------------------------------------ a transition between two actions
obj, motion, keys = walk_session.setup(mf, fps=30, every=1, container=False)
walk = obj.animation_data.action
into = walk.copy()
into.name = "walk_b"
check(not addon.MOTIONFIELD_OT_transition.poll(bpy.context), "no second action chosen: the button is greyed")
s.transition_action, s.transition_frames, s.transition_place, s.method = into, 20, 'AUTO', "interp"
check(bpy.ops.motionfield.transition('EXEC_DEFAULT') == {'FINISHED'}, "transition finished")
act = obj.animation_data.action
check(act.name == walk.name + "_to_walk_b" and walk.use_fake_user, "a new action, the old one kept: %s" % act.name)
n = motion.frame_count
check(tuple(int(f) for f in act.frame_range) == (1, 2 * n + 20), "the clip: A, 20 frames, B: %s" % (act.frame_range,))
check(animation.generated_frames(act) == set(range(n + 1, n + 21)), "the 20 frames between are generated keys")
arm = obj.pose.bones["UpperArm_L"]


def arm_rotation(action, frame):
    obj.animation_data.action = action
    bpy.context.scene.frame_set(frame)
    return arm.rotation_quaternion.copy()


check(all((arm_rotation(act, f) - arm_rotation(walk, f)).magnitude < 1e-4 for f in (1, 30, n)), "A's part as it was")
check(all((arm_rotation(act, n + 20 + f) - arm_rotation(into, f)).magnitude < 1e-4 for f in (1, 30, n)),
      "B's part as it was (its pose; its place continues A)")
obj.animation_data.action = act
hips = {f: obj.pose.bones["Hips"].location.copy() for f in (n - 5, n, n + 21, n + 26) if not bpy.context.scene.frame_set(f)}
ahead = (hips[n + 21] - hips[n]).length
step = ((hips[n] - hips[n - 5]).length + (hips[n + 26] - hips[n + 21]).length) / 10  # A's end and B's start
check(0.7 < ahead / (21 * step) < 1.3, "B's first frame continues A's walk: %.2f m ahead of A's last, %.3f m a frame"
      % (ahead, step))
s.transition_action = act
check(not addon.MOTIONFIELD_OT_transition.poll(bpy.context), "blending an action into itself is greyed")
s.transition_action, s.transition_frames, s.method = None, 0, "DEFAULT"
log("transition")

# ------------------------------------------------------------------ only the methods that can run are offered
with tempfile.TemporaryDirectory() as d:
    alone = os.path.join(d, "prior-alone.mfm")  # the prior without the transformer files next to it
    os.symlink(engine.default_model_path(), alone)
    items = lambda: [i[0] for i in addon._method_items("complete")(s, bpy.context)]  # noqa: E731
    everything = items()
    s.model_path = alone
    check(items() == ["DEFAULT", "interp", "zerovel", "nemf", "nemf-adam"],
          "with the prior alone only its methods are offered: %s" % items())
    check(addon._method_items("complete")(s, bpy.context)[0][1] == "Default (nemf)", "the default is named")
    s.model_path = ""
check(len(everything) == 15 and everything[0] == "DEFAULT", "every method with the bundled models: %s" % everything)
log("methods offered")

# ------------------------------------------------------------------ import and export through the library
# The sample with the joint names of other tools (everything else unchanged).
MIXAMO = {"Chest": "Spine2", "UpperArm": "Arm", "LowerArm": "ForeArm", "UpperLeg": "UpLeg", "LowerLeg": "Leg",
          "Toes": "ToeBase"}
DAZ = {"Hips": "hip", "Spine": "abdomen", "Chest": "chest", "Neck": "neck", "Head": "head", "Shoulder": "Collar",
       "UpperArm": "Shldr", "LowerArm": "ForeArm", "Hand": "Hand", "UpperLeg": "Thigh", "LowerLeg": "Shin",
       "Foot": "Foot", "Toes": "Toe"}  # Daz Studio's Genesis 1 / Poser names


def renamed(name, style):
    part, _, side = name.partition("_")
    if style == "mixamo":
        word = {"L": "Left", "R": "Right"}.get(side, "")
        return "mixamorig:" + word + MIXAMO.get(part, part)
    return side.lower() + DAZ[part]


def styled_sample(style, path):
    with open(walk_session.SAMPLE) as f:
        text = f.read()
    for n in motion.joint_names:
        text = text.replace("JOINT %s\n" % n, "JOINT %s\n" % renamed(n, style))
    with open(path, "w") as f:
        f.write(text)
    return [renamed(n, style) for n in motion.joint_names]


def check_import(path, names):
    """Imports `path` with the operator; the armature's bone heads are the
    library's joint positions on every frame, and the rig maps onto the model's."""
    before = set(bpy.data.objects)
    check(bpy.ops.motionfield.import_motion(filepath=path) == {'FINISHED'}, "import %s" % path)
    new = [o for o in bpy.data.objects if o not in before]
    check(len(new) == 1 and new[0].type == 'ARMATURE', "import made one armature: %s" % new)
    imported, want = new[0], mf.Motion.load(path)
    check(sorted(b.name for b in imported.data.bones) == sorted(names), "bones of %s" % path)
    frames = list(range(1, want.frame_count + 1))
    check(bpy.context.scene.frame_end == want.frame_count and abs(addon._scene_fps(bpy.context.scene) - want.fps)
          < 1e-6, "the scene takes the file's frames and rate")
    err = walk_session.errors(imported, want, frames, names=want.joint_names)
    check(err[0] < 1e-5, "imported %s: bone heads %g m from the file's joints" % (path, err[0]))
    d, error = rig_info.describe(mf, imported, rig_info.root_name(s, imported), 1.0, "", model)
    check(error is None and len(d["map"]) == 21, "%s maps onto the model's rig: %s" % (path, error or d["map"]))
    return imported, want


with tempfile.TemporaryDirectory() as d:
    samples = sorted(glob.glob(os.path.join(os.path.dirname(walk_session.SAMPLE), "*.bvh")))
    files = [(p, list(mf.Motion.load_bvh(p).joint_names)) for p in samples]
    for style in ("mixamo", "daz"):
        path = os.path.join(d, style + ".bvh")
        files.append((path, styled_sample(style, path)))
    glb = os.path.join(d, "walk.glb")  # glTF 2.0 in, through the library's reader
    mf.Motion.load_bvh(walk_session.SAMPLE).save_gltf(glb)
    files.append((glb, list(mf.Motion.load(glb).joint_names)))
    for path, names in files:
        imported, want = check_import(path, names)
    out = os.path.join(d, "export.bvh")
    bpy.context.view_layer.objects.active = imported
    check(bpy.ops.motionfield.export_motion(filepath=out) == {'FINISHED'}, "export")
    back = mf.Motion.load_bvh(out)
    order = [list(back.joint_names).index(n) for n in want.joint_names]
    err = float(abs(back.global_positions[:, order] - want.global_positions).max())
    check(back.frame_count == want.frame_count and err < 1e-4, "export gives the joints back: %g m" % err)
log("import and export")

# ------------------------------------------------------------------ the panel an animator reads
check(addon.progress_text("In-between", (180, 5030, 1, 3)) ==
      "motionfield In-between: window 2 of 3, iteration 180 (at most 5030) (Esc cancels)", "progress text")
check(addon.progress_text("Fill gap", (0, 0, 0, 0)) == "motionfield Fill gap: working (Esc cancels)", "no progress yet")
check(addon.progress_fraction((180, 5030, 1, 3)) == 1 / 3 and addon.progress_fraction((5, 10, 0, 0)) == 0.5,
      "the bar counts windows, else the budget")
long_error = "motionfield: " + "cannot map this skeleton onto the model's humanoid " * 6
check(all(len(line) <= 72 for line in addon.panel.wrap(long_error).split("\n")), "errors are wrapped")
scene = bpy.context.scene
obj, motion, keys = walk_session.setup(mf, fps=24, container=False)
check(addon.source_fps(bpy.context, obj) == (30.0, 24.0), "the source rate is the imported file's")
check(bpy.ops.motionfield.resample.poll(), "resample offered from 30 to 24 fps")
scene.render.fps = 30
check(not bpy.ops.motionfield.resample.poll(), "no resampling from 30 to 30 fps")
s.source_fps = 60.0
check(addon.source_fps(bpy.context, obj) == (60.0, 30.0) and bpy.ops.motionfield.resample.poll(), "a set source rate")
s.source_fps = 0.0
check(not bpy.ops.motionfield.follow_path.poll(), "follow path needs a curve")
check(addon._method_items("complete")(s, bpy.context)[0][1] == "Default (%s)" % mf.default_method(),
      "the default method is named")


class Layout:
    """Stands in for UILayout in background mode (no window to draw in):
    records the labels and operators the panels draw."""

    def __init__(self, out):
        self.out = out

    def __getattr__(self, name):
        def call(*a, **kw):
            if name in ("label", "operator"):
                self.out.append((name, kw.get("text") or a[0]))
            return Layout(self.out)
        return call


drawn = []
for cls in addon.panel.CLASSES:
    cls.draw(type("P", (), {"layout": Layout(drawn)})(), bpy.context)
texts = [t for _, t in drawn]
check(texts[:3] == ["motionfield.inbetween", "motionfield.fill", "motionfield.clear_generated"],
      "the main buttons come first: %s" % texts[:3])
check("Root bone: Hips (found)" in texts and any(t.startswith("Rig map: 21 of 21") for t in texts),
      "the panel names the root and the rig map: %s" % texts)
check("From 30 fps to 30 fps" in texts, "the panel says the source rate")
log("panel")

addon.unregister()
finish()
