"""motionfield for Blender: in-betweening, gap filling, resampling and
re-navigation of the active armature's action with motionfield's learned
motion prior (libmotionfield.so through the motionfield Python package).

The 3D view's side panel (N), tab "motionfield". Every operator reads the
armature frame by frame (any humanoid rig: the library maps it onto the
model's rig, see docs/RIGS.md), runs one task and writes keys as one undo
step, touching only the active armature's action:

* In-between: solves every frame between the keyed ones (in the scene's
  range, the preview range or the span of the selected keys) and keys only
  the frames that were not keyed;
* Fill gap: the unkeyed frames around the current frame, between two keyed
  ranges;
* Resample: the keyed span, taken at the given source frame rate, to the
  scene's frame rate, into a copy of the action;
* Follow path: a new walk in the action's style along a curve object's
  ground path, into a copy of the action;
* Transition: the end of the action into the start of a second action of
  the armature, with generated frames between them, into a new action.
"""

bl_info = {
    "name": "motionfield",
    "author": "motionfield contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D View > Sidebar (N) > motionfield",
    "description": "Learned motion prior: in-betweening, gap filling, resampling, path following",
    "category": "Animation",
}

import time

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import alternatives, animation, convert, engine, motion_io, panel, rig_info

# ------------------------------------------------------------------ preferences


class MOTIONFIELD_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = __name__

    python_dir: StringProperty(
        name="Python package folder", subtype='DIR_PATH',
        description="Folder holding the motionfield Python package (e.g. <checkout>/python); "
                    "empty: $MOTIONFIELD_PYTHON, an installed package, or next to the add-on. "
                    "Read once: a change takes effect after restarting Blender")
    library: StringProperty(
        name="Library", subtype='FILE_PATH',
        description="libmotionfield.so to use (sets $MOTIONFIELD_LIBRARY before the first use); "
                    "empty: the package finds it. A change takes effect after restarting Blender")

    def draw(self, context):
        self.layout.prop(self, "python_dir")
        self.layout.prop(self, "library")
        try:
            mf = _mf()
            self.layout.label(text="motionfield %s: %s" % (mf.version(), mf.library_path()))
        except Exception as e:  # shown, not raised
            self.layout.label(text=str(e), icon='ERROR')


def _prefs():
    addon = bpy.context.preferences.addons.get(__name__)
    return addon.preferences if addon else None


def _mf():
    p = _prefs()
    return engine.load(bpy.path.abspath(p.python_dir) if p and p.python_dir else "",
                       bpy.path.abspath(p.library) if p and p.library else "")


# ------------------------------------------------------------------ settings

_enum_keep = {}  # Blender needs the enum item strings kept alive


def _default_label(kind, mf, model):
    if kind == "complete":
        return mf.default_method(model=model)
    if kind == "resample":
        return "prior" if model is not None else "cubic"
    return "nemf"


def _method_items(kind):
    """The enum items of the methods for `kind` that can run with the settings'
    model: a method whose transformer file is missing is not offered."""
    def items(self, context):
        out = []
        try:
            mf = _mf()
            model = engine.model_or_none(bpy.path.abspath(self.model_path))
            out.append(("DEFAULT", "Default (%s)" % _default_label(kind, mf, model),
                        "The library's default method for this task with the model"))
            for m in mf.methods():
                if ((kind == "complete" and m.completes) or (kind == "resample" and m.resamples)) and \
                        engine.can_run(m, model):
                    out.append((m.name, m.name, m.description))
        except Exception:  # the package is missing: the panel says so
            out = out or [("DEFAULT", "Default", "The library's default method for this task")]
        if kind == "renav":
            out += [("nemf", "nemf", "L-BFGS on the prior's latent codes"),
                    ("nemf-adam", "nemf-adam", "NeMF's Adam reference (slower)")]
        _enum_keep[kind] = out
        return out
    return items


def _is_curve(self, obj):
    return obj.type == 'CURVE'


class MotionfieldSettings(bpy.types.PropertyGroup):
    method: EnumProperty(name="Method", items=_method_items("complete"),
                         description="In-betweening and gap-filling method (mf_method_get)")
    resample_method: EnumProperty(name="Resample method", items=_method_items("resample"))
    path_method: EnumProperty(name="Path method", items=_method_items("renav"))
    model_path: StringProperty(name="Model", subtype='FILE_PATH',
                               description="Model file (.mfm); empty: the bundled default model "
                                           "(mf_model_default_path)")
    rig_map: StringProperty(name="Rig map", subtype='FILE_PATH',
                            description="JSON rig map {armature bone: model joint or null} overriding the "
                                        "automatic map (docs/RIGS.md); empty: automatic")
    root_bone: StringProperty(name="Root bone",
                              description="The bone whose translation moves the character; its tree is "
                                          "converted. Empty: found from the action (the first bone below "
                                          "static container bones that moves)")
    alternatives: IntProperty(name="Alternatives", min=0, max=8, default=0,
                              description="More solutions of In-between and Fill gap from other starts, to cycle "
                                          "through with Previous / Next (the latent solvers only: the nemf methods)")
    seed: IntProperty(name="Seed", min=0, default=0)
    max_iterations: IntProperty(name="Iterations", min=0, default=0,
                                description="Iteration budget of the solvers (per window of the full solve); "
                                            "0: each method's own (mf_task_options.max_iterations)")
    range_mode: EnumProperty(name="Range", default='SCENE', items=[
        ('SCENE', "Scene", "Every frame between keys in the scene's frame range"),
        ('PREVIEW', "Preview", "Within the preview range (the scene range when off)"),
        ('SELECTED', "Selected keys", "Within the span of the selected keys"),
    ])
    source_fps: FloatProperty(name="Source frame rate", default=0.0, min=0.0, max=1000.0,
                              description="Frame rate the action's frames were sampled at (one frame each); "
                                          "0: the action's own (its file's, when imported with motionfield), "
                                          "else the scene's")
    path_object: PointerProperty(name="Path", type=bpy.types.Object, poll=_is_curve,
                                 description="Curve object whose ground path (first spline) to follow")
    transition_action: PointerProperty(name="Into action", type=bpy.types.Action,
                                       description="The action whose start the armature's action blends into")
    transition_frames: IntProperty(name="Frames", min=0, max=600, default=0,
                                   description="Generated frames between the two actions; 0: chosen from the change "
                                               "of pose (10-60 at 30 fps, reported)")
    transition_place: EnumProperty(name="Placement", default='AUTO', items=[
        ('AUTO', "Continue", "Move and turn the second action on the ground so that it continues the first"),
        ('KEEP', "Keep", "Leave the second action where it is")])


# ------------------------------------------------------------------ operators


def _scene_fps(scene):
    return scene.render.fps / scene.render.fps_base


def source_fps(context, obj):
    """(the frame rate the action's frames are taken at, the scene's)."""
    scene = context.scene
    fps = scene.motionfield.source_fps or obj.animation_data.action.get(motion_io.FPS_PROP, 0.0)
    return (fps or _scene_fps(scene)), _scene_fps(scene)


def progress_text(label, progress):
    """The status bar's line for (iteration, max_iterations, window, window_count):
    the budget is an upper bound (the solvers stop when they converge)."""
    i, n, w, count = progress
    parts = ["window %d of %d" % (w + 1, count)] if count > 1 else []
    if n:
        parts.append("iteration %d (at most %d)" % (i, n))
    return "motionfield %s: %s (Esc cancels)" % (label, ", ".join(parts) or "working")


def progress_fraction(progress):
    """0..1 for the progress bar: windows done when solved in windows, else the budget used."""
    i, n, w, count = progress
    if count > 1:
        return w / count
    return min(1.0, i / n) if n else 0.0


def _method_arg(value):
    return None if value in ("", "DEFAULT") else value


REDRAWN = {'VIEW_3D', 'DOPESHEET_EDITOR', 'GRAPH_EDITOR', 'NLA_EDITOR', 'TIMELINE'}


def redraw(context):
    """Tags the 3D views and the animation editors of every window for redraw:
    new keys show at once, not at the next scrub."""
    for window in context.window_manager.windows:
        for area in window.screen.areas:
            if area.type in REDRAWN:
                area.tag_redraw()


def has_action(cls, context):
    """Whether the active object is an armature with an action; else says why
    on the greyed button (poll_message_set)."""
    obj = context.active_object
    why = ("Select an armature" if obj is None or obj.type != 'ARMATURE' else
           "The armature has no action: key a few poses first"
           if obj.animation_data is None or obj.animation_data.action is None else None)
    if why and hasattr(cls, "poll_message_set"):
        cls.poll_message_set(why)
    return why is None


class _TaskOperator:
    """prepare() reads the armature and returns (run, finish); execute() runs
    inline (scripts, background mode), invoke() on a thread with Esc."""

    bl_options = {'REGISTER', 'UNDO'}
    completes = False  # an in-betweening / gap-filling operator (its default method is mf_default_method's)
    method_label = ""

    @classmethod
    def poll(cls, context):
        return has_action(cls, context)

    def _setup(self, context):
        s = context.scene.motionfield
        self.mf = _mf()
        self.obj = context.active_object
        self.rig = convert.Rig(self.obj, rig_info.root_name(s, self.obj),
                               convert.metres_per_unit(context.scene, self.obj))
        self.keyed = animation.keyed_frames(self.obj, self.rig.names)
        if len(self.keyed) < 2:
            raise ValueError("the action has fewer than two keyed frames on the rig's bones")

    def task_kwargs(self, context, method):
        s = context.scene.motionfield
        m = _method_arg(method)
        needs = m is None or any(x.name == m and x.needs_model for x in self.mf.methods())
        kw = {"method": m, "seed": s.seed, "max_iterations": s.max_iterations,
              "model": engine.model(bpy.path.abspath(s.model_path)) if needs else None}
        self.method_label = m or (self.mf.default_method(model=kw["model"]) if self.completes else "the default method")
        if s.rig_map:
            kw["rig_map"] = bpy.path.abspath(s.rig_map)
        return kw

    def completion(self, context, motion, known, sampled, new):
        """(run, finish) of In-between and Fill gap: complete `motion` from its
        frames `known` (indices into `sampled`), key the frames `new` as generated
        keys; with alternatives, through motionfield.solve, keeping them to cycle."""
        s = context.scene.motionfield
        kw = self.task_kwargs(context, s.method)
        count = s.alternatives

        def run(progress, cancel):
            if count:
                return self.mf.solve(motion, known, alternatives=count, progress=progress, cancel=cancel, **kw)
            return self.mf.inbetween(motion, known, progress=progress, cancel=cancel, **kw)

        def key(result):
            motions = result.motions if count else [result]
            if count:
                self.method_label = result.method
            values = animation.channel_values(self.obj, self.rig, sampled, motions[0].rotations,
                                              motions[0].root_positions, new)
            animation.insert_keys(self.obj, self.rig, sampled, values, new, set(self.keyed))
            alternatives.remember(self.obj, self.rig, sampled, new, self.keyed, motions)
            return " (alternative 1 of %d)" % len(motions) if count else ""
        return run, key

    def motion(self, sampled, fps):
        return self.mf.Motion.from_arrays(sampled.rotations, sampled.root_positions, fps,
                                          joint_names=self.rig.names, parents=self.rig.parents,
                                          offsets=self.rig.offsets)

    def _start(self, context):
        self._t0 = time.time()
        try:
            self._setup(context)
            run, self._finish = self.prepare(context)
            self._job = engine.Job(run)
        except Exception as e:
            self.report({'ERROR'}, panel.wrap("motionfield: %s" % e))
            return False
        return True

    def _end(self, context):
        wm = context.window_manager
        wm.progress_end()
        redraw(context)
        job = self._job
        if job.error is not None:
            cancelled = isinstance(job.error, self.mf.CancelledError)
            self.report({'WARNING'} if cancelled else {'ERROR'},
                        "motionfield: cancelled, nothing changed" if cancelled else
                        panel.wrap("motionfield: %s" % job.error))
            return {'CANCELLED'}
        message = self._finish(context, job.result)
        redraw(context)
        warnings = job.result.warnings
        if warnings:
            text = warnings if isinstance(warnings, str) else " ".join(warnings)
            self.report({'WARNING'}, panel.wrap("motionfield: %s" % text))
        self.report({'INFO'}, "motionfield: %s with %s in %.1f s" % (message, self.method_label or "the default method",
                                                                     time.time() - self._t0))
        return {'FINISHED'}

    def execute(self, context):
        if not self._start(context):
            return {'CANCELLED'}
        wm = context.window_manager
        wm.progress_begin(0, 100)

        def shown(progress):
            wm.progress_update(int(100 * progress_fraction(progress)))
            return False
        self._job.run_inline(shown)
        return self._end(context)

    def invoke(self, context, event):
        if not self._start(context):
            return {'CANCELLED'}
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        self._job.start()
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        job = self._job
        if event.type == 'ESC':
            job.cancel()
        if event.type != 'TIMER':
            return {'RUNNING_MODAL'} if not job.done else {'PASS_THROUGH'}
        context.window_manager.progress_update(int(100 * progress_fraction(job.progress)))
        context.workspace.status_text_set(progress_text(self.bl_label, job.progress))
        if not job.done:
            return {'RUNNING_MODAL'}
        job.join()
        context.window_manager.event_timer_remove(self._timer)
        context.workspace.status_text_set(None)
        return self._end(context)


def _range(scene, s, obj, names):
    if s.range_mode == 'PREVIEW' and scene.use_preview_range:
        return scene.frame_preview_start, scene.frame_preview_end
    if s.range_mode == 'SELECTED':
        sel = animation.selected_key_frames(obj, names)
        if len(sel) < 2:
            raise ValueError("select at least two keys (Dope Sheet / Graph Editor)")
        return sel[0], sel[-1]
    return scene.frame_start, scene.frame_end


class MOTIONFIELD_OT_inbetween(_TaskOperator, bpy.types.Operator):
    """Solve the frames between the animator's keys as generated keys (breakdowns), replacing earlier generated ones"""
    bl_idname = "motionfield.inbetween"
    bl_label = "In-between"

    completes = True

    def prepare(self, context):
        scene, s = context.scene, context.scene.motionfield
        lo, hi = _range(scene, s, self.obj, self.rig.names)
        keys = [k for k in self.keyed if lo <= k <= hi]
        if len(keys) < 2:
            raise ValueError("fewer than two keyed frames in frames %d..%d" % (lo, hi))
        frames = list(range(keys[0], keys[-1] + 1))
        new = set(frames) - set(keys)
        if not new:
            raise ValueError("every frame in %d..%d is keyed already" % (keys[0], keys[-1]))
        sampled = convert.read_frames(scene, self.obj, self.rig, frames)
        motion = self.motion(sampled, _scene_fps(scene))
        run, key = self.completion(context, motion, [k - keys[0] for k in keys], sampled, new)

        def finish(context, result):
            chosen = key(result)
            return "keyed %d frames between frames %d and %d%s" % (len(new), keys[0], keys[-1], chosen)
        return run, finish


def _gap_around(keyed, frame):
    """(first, last) unkeyed frames around `frame` between two keys, else None."""
    before = [k for k in keyed if k < frame]
    after = [k for k in keyed if k > frame]
    if frame in keyed or not before or not after:
        return None
    return before[-1] + 1, after[0] - 1


def _run_edge(keyed, start, step, limit):
    """The far end of the run of consecutive keyed frames from `start` going `step`."""
    ks = set(keyed)
    f = start
    while f + step in ks and abs(f + step - start) < limit:
        f += step
    return f


class MOTIONFIELD_OT_fill(_TaskOperator, bpy.types.Operator):
    """Fill the unkeyed frames around the current frame, between two keyed ranges"""
    bl_idname = "motionfield.fill"
    bl_label = "Fill gap"

    CONTEXT_FRAMES = 60
    completes = True

    def prepare(self, context):
        scene, s = context.scene, context.scene.motionfield
        gap = _gap_around(self.keyed, scene.frame_current)
        if gap is None:
            raise ValueError("put the current frame in a gap of unkeyed frames between two keyed ranges")
        a = _run_edge(self.keyed, gap[0] - 1, -1, self.CONTEXT_FRAMES)
        b = _run_edge(self.keyed, gap[1] + 1, 1, self.CONTEXT_FRAMES)
        frames = list(range(a, b + 1))
        new = set(range(gap[0], gap[1] + 1))
        sampled = convert.read_frames(scene, self.obj, self.rig, frames)
        motion = self.motion(sampled, _scene_fps(scene))
        known = [f - a for f in frames if f not in new]  # the gap filled from everything around it, as mf.fill does
        run, key = self.completion(context, motion, known, sampled, new)

        def finish(context, result):
            return "keyed %d frames (%d..%d)%s" % (len(new), gap[0], gap[1], key(result))
        return run, finish


class MOTIONFIELD_OT_resample(_TaskOperator, bpy.types.Operator):
    """Resample the keyed span, sampled at the source frame rate, to the scene's frame rate, into a copy of the action"""
    bl_idname = "motionfield.resample"
    bl_label = "Resample"

    @classmethod
    def poll(cls, context):
        if not has_action(cls, context):
            return False
        source, fps = source_fps(context, context.active_object)
        if abs(source - fps) < 1e-6:
            cls.poll_message_set("The source frame rate is the scene's (%g fps): set it under Resample" % fps)
            return False
        return True

    def prepare(self, context):
        scene, s = context.scene, context.scene.motionfield
        source, fps = source_fps(context, self.obj)
        if abs(source - fps) < 1e-6:
            raise ValueError("the source frame rate is the scene's (%g): nothing to resample" % fps)
        frames = list(range(self.keyed[0], self.keyed[-1] + 1))
        sampled = convert.read_frames(scene, self.obj, self.rig, frames)
        motion = self.motion(sampled, source)
        kw = self.task_kwargs(context, s.resample_method)

        def run(progress, cancel):
            return self.mf.resample(motion, fps, progress=progress, cancel=cancel, **kw)

        def finish(context, result):
            act = animation.new_action_with(self.obj, self.rig, result.rotations, result.root_positions,
                                            frames[0], ".%gfps" % fps, sampled.parent_poses[0])
            return "%d frames at %g fps in action %r" % (result.frame_count, fps, act.name)
        return run, finish


def curve_ground_path(context, curve, armature, scale):
    """The curve's first spline, evaluated, as [points, 2] ground (x, z) in
    the armature's motion space (metres)."""
    import numpy as np
    deps = context.evaluated_depsgraph_get()
    ev = curve.evaluated_get(deps)
    mesh = ev.to_mesh()
    try:
        to_arm = armature.matrix_world.inverted() @ curve.matrix_world
        pts = [convert.C3 @ (to_arm @ v.co) * scale for v in mesh.vertices]
    finally:
        ev.to_mesh_clear()
    if len(pts) < 2:
        raise ValueError("curve %r has fewer than two points" % curve.name)
    return np.array([(p.x, p.z) for p in pts], dtype=np.float32)


class MOTIONFIELD_OT_follow_path(_TaskOperator, bpy.types.Operator):
    """A motion in the action's style whose root follows the path curve, into a copy of the action"""
    bl_idname = "motionfield.follow_path"
    bl_label = "Follow path"

    @classmethod
    def poll(cls, context):
        if not has_action(cls, context):
            return False
        if context.scene.motionfield.path_object is None:
            cls.poll_message_set("Choose a path curve first")
            return False
        return True

    def prepare(self, context):
        scene, s = context.scene, context.scene.motionfield
        if s.path_object is None:
            raise ValueError("choose a curve object as the path")
        fps = _scene_fps(scene)
        xz = curve_ground_path(context, s.path_object, self.obj, self.rig.scale)
        frames = list(range(self.keyed[0], self.keyed[-1] + 1))
        sampled = convert.read_frames(scene, self.obj, self.rig, frames)
        motion = self.motion(sampled, fps)
        kw = self.task_kwargs(context, s.path_method)
        if kw["model"] is None:
            kw["model"] = engine.model(bpy.path.abspath(s.model_path))

        def run(progress, cancel):
            return self.mf.renav(motion, xz, polyline=True, fps=fps, progress=progress, cancel=cancel, **kw)

        def finish(context, result):
            act = animation.new_action_with(self.obj, self.rig, result.rotations, result.root_positions,
                                            frames[0], ".path", sampled.parent_poses[0])
            return "%d frames along %r in action %r" % (result.frame_count, s.path_object.name, act.name)
        return run, finish


def read_action(context, obj, rig, action):
    """The armature's pose over the keyed span of `action` (convert.read_frames),
    played on it for the reading; its own action is back afterwards."""
    own = obj.animation_data.action
    obj.animation_data.action = action
    try:
        keyed = animation.keyed_frames(obj, rig.names)
        if len(keyed) < 2:
            raise ValueError("action %r has fewer than two keyed frames on the rig's bones" % action.name)
        return convert.read_frames(context.scene, obj, rig, list(range(keyed[0], keyed[-1] + 1)))
    finally:
        obj.animation_data.action = own


class MOTIONFIELD_OT_transition(_TaskOperator, bpy.types.Operator):
    """Blend the end of the armature's action into the start of a second action, generated frames between them, into a new action"""
    bl_idname = "motionfield.transition"
    bl_label = "Transition"

    completes = True

    @classmethod
    def poll(cls, context):
        if not has_action(cls, context):
            return False
        into = context.scene.motionfield.transition_action
        why = ("Choose the action to blend into" if into is None else
               "Choose another action than the armature's own"
               if into == context.active_object.animation_data.action else None)
        if why:
            cls.poll_message_set(why)
        return why is None

    def prepare(self, context):
        scene, s = context.scene, context.scene.motionfield
        first, into = self.obj.animation_data.action, s.transition_action
        if into is None or into == first:
            raise ValueError("choose a second action of the armature to blend into (Transition > Into action)")
        frames = list(range(self.keyed[0], self.keyed[-1] + 1))
        sampled = convert.read_frames(scene, self.obj, self.rig, frames)
        second = read_action(context, self.obj, self.rig, into)
        fps = _scene_fps(scene)
        a, b = self.motion(sampled, fps), self.motion(second, fps)
        kw = self.task_kwargs(context, s.method)
        length = s.transition_frames or None

        def run(progress, cancel):
            return self.mf.transition(a, b, length, place=s.transition_place.lower(), progress=progress,
                                      cancel=cancel, **kw)

        def finish(context, result):
            self.method_label = result.method
            m = result.motion
            act = animation.new_action_with(self.obj, self.rig, m.rotations, m.root_positions, frames[0],
                                            "_to_" + into.name, sampled.parent_poses[0])
            start = frames[0] + result.first_frame
            animation.mark_generated(self.obj, act, range(start, start + result.frames))
            return "%d frames between %r and %r (frames %d..%d) in action %r" % (
                result.frames, first.name, into.name, start, start + result.frames - 1, act.name)
        return run, finish


class MOTIONFIELD_OT_clear_generated(bpy.types.Operator):
    """Remove the keys In-between and Fill gap generated from the active armature's action (the animator's keys stay)"""
    bl_idname = "motionfield.clear_generated"
    bl_label = "Clear generated"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return has_action(cls, context)

    def execute(self, context):
        n = animation.clear_generated(context.active_object)
        redraw(context)
        self.report({'INFO'}, "motionfield: removed the generated keys of %d frames" % n)
        return {'FINISHED'}


class MOTIONFIELD_OT_alternative(bpy.types.Operator):
    """Key another of the last In-between's or Fill gap's alternative solutions on its generated frames"""
    bl_idname = "motionfield.alternative"
    bl_label = "Alternative"
    bl_options = {'REGISTER', 'UNDO'}

    step: IntProperty(name="Step", default=1, description="+1: the next alternative, -1: the previous one")

    @classmethod
    def poll(cls, context):
        if not has_action(cls, context):
            return False
        if alternatives.current(context.active_object) is None:
            cls.poll_message_set("Run In-between or Fill gap with Alternatives above 0 first (Advanced); "
                                 "editing a key forgets them")
            return False
        return True

    def execute(self, context):
        try:
            index, count = alternatives.step(context.active_object, self.step)
        except ValueError as e:
            self.report({'ERROR'}, panel.wrap("motionfield: %s" % e))
            return {'CANCELLED'}
        redraw(context)
        self.report({'INFO'}, "motionfield: alternative %d of %d" % (index + 1, count))
        return {'FINISHED'}


class MOTIONFIELD_OT_set_root(bpy.types.Operator):
    """Use this bone as the root bone (empty: find the root from the action)"""
    bl_idname = "motionfield.set_root"
    bl_label = "Set root bone"
    bl_options = {'REGISTER', 'UNDO'}

    bone: StringProperty(name="Bone")

    def execute(self, context):
        context.scene.motionfield.root_bone = self.bone
        return {'FINISHED'}


# ------------------------------------------------------------------ import and export

UNIT_ITEMS = [("auto", "Automatic", "From the leg length (centimetres when no legs are found)"),
              ("cm", "Centimetres", ""), ("m", "Metres", ""), ("mm", "Millimetres", ""), ("in", "Inches", "")]


class MOTIONFIELD_OT_import_motion(bpy.types.Operator, ImportHelper):
    """Import a motion (BVH, glTF 2.0 or FBX) as an armature and its action with motionfield's readers (any Python version)"""
    bl_idname = "motionfield.import_motion"
    bl_label = "Import motion (motionfield)"
    bl_options = {'REGISTER', 'UNDO'}

    filename_ext = ".bvh"
    filter_glob: StringProperty(default="*.bvh;*.glb;*.gltf;*.fbx", options={'HIDDEN'})
    units: EnumProperty(name="File units (BVH)", items=UNIT_ITEMS, default="auto")
    rotation_mode: EnumProperty(name="Rotation", default='QUATERNION', items=[
        ('QUATERNION', "Quaternion", "Bones rotate in quaternions"),
        ('XYZ', "Euler XYZ", "Bones rotate in XYZ Euler angles")])
    use_scene_fps: BoolProperty(name="Scene frame rate from the file", default=True,
                                description="Set the scene's frame rate to the file's and its frame range to the "
                                            "motion's (one key a frame either way)")

    def execute(self, context):
        try:
            if context.object is not None and context.object.mode != 'OBJECT':
                bpy.ops.object.mode_set(mode='OBJECT')
            obj, motion = motion_io.import_motion(context, _mf(), self.filepath, self.units, self.rotation_mode)
        except Exception as e:
            self.report({'ERROR'}, panel.wrap("motionfield: %s" % e))
            return {'CANCELLED'}
        scene = context.scene
        if self.use_scene_fps:
            fps = max(1, round(motion.fps))
            scene.render.fps, scene.render.fps_base = fps, fps / motion.fps
            scene.frame_end = scene.frame_start + motion.frame_count - 1
        redraw(context)
        self.report({'INFO'}, "motionfield: imported %r: %d joints, %d frames at %g fps"
                    % (obj.name, motion.joint_count, motion.frame_count, motion.fps))
        return {'FINISHED'}


class MOTIONFIELD_OT_export_motion(bpy.types.Operator, ExportHelper):
    """Export the active armature's action as BVH with motionfield's writer (metres, the armature's rest pose)"""
    bl_idname = "motionfield.export_motion"
    bl_label = "Export motion (motionfield)"

    filename_ext = ".bvh"
    filter_glob: StringProperty(default="*.bvh", options={'HIDDEN'})

    @classmethod
    def poll(cls, context):
        return has_action(cls, context)

    def execute(self, context):
        obj, scene = context.active_object, context.scene
        first, last = (int(round(f)) for f in obj.animation_data.action.frame_range)
        try:
            motion = motion_io.export_motion(context, _mf(), obj, rig_info.root_name(scene.motionfield, obj),
                                             self.filepath, list(range(first, last + 1)), _scene_fps(scene))
        except Exception as e:
            self.report({'ERROR'}, panel.wrap("motionfield: %s" % e))
            return {'CANCELLED'}
        self.report({'INFO'}, "motionfield: wrote %d frames to %s" % (motion.frame_count, self.filepath))
        return {'FINISHED'}


def _menu_import(self, context):
    self.layout.operator(MOTIONFIELD_OT_import_motion.bl_idname, text="Motion (motionfield) (.bvh, .glb, .fbx)")


def _menu_export(self, context):
    self.layout.operator(MOTIONFIELD_OT_export_motion.bl_idname, text="Motion (motionfield) (.bvh)")


_classes = (MOTIONFIELD_AP_preferences, MotionfieldSettings, MOTIONFIELD_OT_set_root, MOTIONFIELD_OT_inbetween,
            MOTIONFIELD_OT_fill, MOTIONFIELD_OT_clear_generated, MOTIONFIELD_OT_alternative, MOTIONFIELD_OT_import_motion,
            MOTIONFIELD_OT_export_motion, MOTIONFIELD_OT_resample, MOTIONFIELD_OT_follow_path,
            MOTIONFIELD_OT_transition) + panel.CLASSES


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.motionfield = PointerProperty(type=MotionfieldSettings)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    del bpy.types.Scene.motionfield
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
