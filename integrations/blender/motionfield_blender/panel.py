"""The 3D view's sidebar tab "motionfield": the main buttons first, then the
rig, resampling, path following, files, and the advanced settings folded.

Every label sits on a line of its own above its field, so that nothing is
cut at the sidebar's default width; long messages are wrapped to it.
"""

import textwrap

import bpy

from . import alternatives, convert, engine, rig_info

CHARS_PER_PIXEL = 1.0 / 8.0  # a rough width of the interface font's characters


def wrap(text, width=72):
    """`text` in lines of at most `width` characters (reports, labels)."""
    return "\n".join(textwrap.wrap(text, width) or [""])


def wrapped_label(layout, context, text, icon='NONE'):
    """A label over as many lines as the region's width needs."""
    width = 40
    region = getattr(context, "region", None)
    if region is not None and region.width > 0:
        # less the tabs, the margins and the icon
        width = max(20, int((region.width - 60) * CHARS_PER_PIXEL / context.preferences.view.ui_scale))
    col = layout.column(align=True)
    for i, line in enumerate(wrap(text, width).split("\n")):
        col.label(text=line, icon=icon if i == 0 else 'BLANK1' if icon != 'NONE' else 'NONE')


def field(layout, data, prop, label):
    """A label on its own line, the field under it at full width."""
    col = layout.column(align=True)
    col.label(text=label)
    col.prop(data, prop, text="")
    return col


class _Panel:
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "motionfield"


class _SubPanel(_Panel):
    """A folded panel under the main one."""
    bl_parent_id = "MOTIONFIELD_PT_main"
    bl_options = {'DEFAULT_CLOSED'}


def package_or_error(layout, context):
    from . import _mf
    try:
        return _mf()
    except Exception as e:  # shown, not raised
        wrapped_label(layout, context, str(e), 'ERROR')
        return None


class MOTIONFIELD_PT_main(_Panel, bpy.types.Panel):
    bl_label = "motionfield"

    def draw(self, context):
        layout, s = self.layout, context.scene.motionfield
        mf = package_or_error(layout, context)
        if mf is None:
            return
        col = layout.column(align=True)
        col.scale_y = 1.4
        row = col.row(align=True)
        row.operator("motionfield.inbetween", icon='IPO_BEZIER')
        row.operator("motionfield.fill", icon='SEQ_STRIP_DUPLICATE')
        layout.operator("motionfield.clear_generated", icon='TRASH')
        draw_alternatives(layout, context)
        field(layout, s, "method", "Method")
        field(layout, s, "range_mode", "Frames")
        field(layout, s, "alternatives", "Alternatives (0: one answer)")
        draw_rig(layout, context, mf)


def draw_alternatives(layout, context):
    """Previous / Next over the last run's alternatives, when it made some."""
    state = alternatives.current(context.active_object)
    if state is None:
        return
    row = layout.row(align=True)
    row.operator("motionfield.alternative", text="", icon='TRIA_LEFT').step = -1
    row.label(text="Alternative %d of %d" % (state[0] + 1, state[1]))
    row.operator("motionfield.alternative", text="", icon='TRIA_RIGHT').step = 1


def draw_rig(layout, context, mf):
    """The rig box: the root bone (found or set, with a one-click change) and
    the library's map of the rig onto the model's."""
    s, obj = context.scene.motionfield, context.active_object
    box = layout.box()
    box.label(text="Rig", icon='ARMATURE_DATA')
    if obj is None or obj.type != 'ARMATURE':
        box.label(text="Select an armature")
        return
    try:
        root = rig_info.root_name(s, obj)
    except convert.RigError as e:
        wrapped_label(box, context, str(e), 'ERROR')
        return
    box.label(text="Root bone: %s (%s)" % (root, "set" if s.root_bone else "found"), icon='BONE_DATA')
    active = getattr(context, "active_bone", None)
    if s.root_bone:
        box.operator("motionfield.set_root", text="Find the root bone", icon='LOOP_BACK').bone = ""
    elif active is not None and active.name != root:
        box.operator("motionfield.set_root", text="Use %s as the root" % active.name, icon='EYEDROPPER').bone = \
            active.name
    try:
        model = engine.model(bpy.path.abspath(s.model_path))
    except Exception as e:  # no model: the map cannot be told
        wrapped_label(box, context, "Model: %s" % e, 'ERROR')
        return
    d, error = rig_info.describe(mf, obj, root, convert.metres_per_unit(context.scene, obj),
                                 bpy.path.abspath(s.rig_map) if s.rig_map else "", model)
    if error:
        wrapped_label(box, context, "Rig map: %s" % error, 'ERROR')
    else:
        wrapped_label(box, context, "Rig map: " + rig_info.summary(d), 'CHECKMARK')


class MOTIONFIELD_PT_resample(_SubPanel, bpy.types.Panel):
    bl_label = "Resample"
    bl_options = set()  # open: the second task an animator looks for

    def draw(self, context):
        from . import source_fps
        layout, s = self.layout, context.scene.motionfield
        field(layout, s, "resample_method", "Method")
        field(layout, s, "source_fps", "Source fps (0: the action's)")
        obj = context.active_object
        if obj is not None and obj.animation_data is not None and obj.animation_data.action is not None:
            layout.label(text="From %g fps to %g fps" % source_fps(context, obj))
        layout.operator("motionfield.resample", icon='TIME')


class MOTIONFIELD_PT_path(_SubPanel, bpy.types.Panel):
    bl_label = "Follow path"

    def draw(self, context):
        layout, s = self.layout, context.scene.motionfield
        field(layout, s, "path_method", "Method")
        field(layout, s, "path_object", "Path curve")
        layout.operator("motionfield.follow_path", icon='CURVE_PATH')


class MOTIONFIELD_PT_transition(_SubPanel, bpy.types.Panel):
    bl_label = "Transition"

    def draw(self, context):
        layout, s = self.layout, context.scene.motionfield
        col = layout.column(align=True)
        col.label(text="Into action")
        col.prop_search(s, "transition_action", bpy.data, "actions", text="")
        field(layout, s, "transition_frames", "Frames (0: chosen)")
        field(layout, s, "transition_place", "Second action")
        layout.operator("motionfield.transition", icon='NLA_PUSHDOWN')


class MOTIONFIELD_PT_files(_SubPanel, bpy.types.Panel):
    bl_label = "Import and export"

    def draw(self, context):
        col = self.layout.column(align=True)
        col.operator("motionfield.import_motion", text="Import motion (.bvh, .glb, .fbx)", icon='IMPORT')
        col.operator("motionfield.export_motion", text="Export action (.bvh)", icon='EXPORT')


class MOTIONFIELD_PT_advanced(_SubPanel, bpy.types.Panel):
    bl_label = "Advanced"

    def draw(self, context):
        layout, s = self.layout, context.scene.motionfield
        field(layout, s, "model_path", "Model (empty: bundled)")
        field(layout, s, "rig_map", "Rig map (empty: automatic)")
        obj = context.active_object
        if obj is not None and obj.type == 'ARMATURE':
            col = layout.column(align=True)
            col.label(text="Root bone (empty: found)")
            col.prop_search(s, "root_bone", obj.data, "bones", text="")
        field(layout, s, "seed", "Seed")
        field(layout, s, "max_iterations", "Iterations (0: the method's)")


CLASSES = (MOTIONFIELD_PT_main, MOTIONFIELD_PT_resample, MOTIONFIELD_PT_path, MOTIONFIELD_PT_transition,
           MOTIONFIELD_PT_files, MOTIONFIELD_PT_advanced)
