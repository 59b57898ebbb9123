"""The add-on's panel drawn in a real window (under a virtual display), before
and after In-between on the sample walk; the pictures are written to
$MF_SCREENSHOT_DIR (panel-before.png, panel-after.png):

    xvfb-run -a -s "-screen 0 1024x640x24" blender --factory-startup --enable-event-simulate \\
      --python-exit-code 1 --python integrations/blender/tests/screenshots.py

A Python error while drawing a panel (Blender prints it and goes on) fails
the run: the add-on's panels open by default must draw, without an error
(the folded ones draw in test_workflow.py on a stand-in layout).
"""

import os
import sys
import traceback

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.environ.get("MF_BLENDER_ADDON_DIR", os.path.dirname(HERE))]
import motionfield_blender as addon  # noqa: E402
import walk_session  # noqa: E402
from motionfield_blender import engine, panel  # noqa: E402

OUT = os.environ.get("MF_SCREENSHOT_DIR", os.getcwd())
ERRORS = []
DRAWN = set()


def guarded(cls):
    """Wraps the panel's draw: an error is recorded (Blender only prints it)."""
    draw = cls.draw

    def checked(self, context):
        try:
            draw(self, context)
            DRAWN.add(cls.__name__)
        except Exception:
            ERRORS.append(traceback.format_exc())
            raise
    cls.draw = checked


def view3d():
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == 'VIEW_3D':
                return window, area
    raise RuntimeError("no 3D view")


def setup():
    mf = engine.load()
    obj, motion, keys = walk_session.setup(mf, fps=24)
    window, area = view3d()
    window.event_simulate('ESC', 'PRESS')  # closes the splash screen
    window.event_simulate('ESC', 'RELEASE')
    obj.select_set(True)
    space = area.spaces.active
    space.show_region_ui = True
    space.region_3d.view_perspective = 'PERSP'
    main = next(r for r in area.regions if r.type == 'WINDOW')
    with bpy.context.temp_override(window=window, area=area, region=main):
        bpy.ops.view3d.view_selected()
    bpy.context.scene.frame_set(11)
    bpy.context.scene.motionfield.alternatives = 2  # the after picture shows the alternatives' row


def show_tab():
    """Ctrl+Tab over the sidebar cycles its tabs (Blender 3.4 has no
    Region.active_panel_category): Item, Tool, View, motionfield (needs
    --enable-event-simulate)."""
    window, area = view3d()
    ui = next(r for r in area.regions if r.type == 'UI')
    x, y = ui.x + ui.width // 2, ui.y + ui.height // 2
    window.event_simulate('MOUSEMOVE', 'NOTHING', x=x, y=y)
    for _ in range(3):
        window.event_simulate('TAB', 'PRESS', x=x, y=y, ctrl=True)
        window.event_simulate('TAB', 'RELEASE', x=x, y=y, ctrl=True)


def shoot(name):
    window, area = view3d()
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screenshot(filepath=os.path.join(OUT, name))


def run_inbetween():
    """As from the button: on a thread, the status bar counting, Esc armed."""
    window, area = view3d()
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.motionfield.inbetween('INVOKE_DEFAULT')


def wait_for_keys(tries=[60]):
    from motionfield_blender import animation
    obj = bpy.context.view_layer.objects.active
    if not animation.generated_frames(obj.animation_data.action):
        tries[0] -= 1
        if not tries[0]:
            raise RuntimeError("In-between did not finish in a minute")
        STEPS.insert(0, wait_for_keys)  # still running: look again in a second
        return
    bpy.context.scene.frame_set(11)


STEPS = [setup, show_tab, lambda: shoot("panel-before.png"), run_inbetween, wait_for_keys,
         lambda: shoot("panel-after.png")]


def step():
    try:
        STEPS.pop(0)()
    except Exception:
        ERRORS.append(traceback.format_exc())
        STEPS.clear()
    if STEPS:
        return 1.0
    missing = {c.__name__ for c in panel.CLASSES if 'DEFAULT_CLOSED' not in getattr(c, "bl_options", ())} - DRAWN
    if missing:
        ERRORS.append("panels never drawn: %s" % sorted(missing))
    for name in ("panel-before.png", "panel-after.png"):
        path = os.path.join(OUT, name)
        if not os.path.isfile(path) or os.path.getsize(path) == 0:
            ERRORS.append("no screenshot %s" % path)
    print("\n".join(ERRORS) or "screenshots: ok, in %s" % OUT, flush=True)
    os._exit(1 if ERRORS else 0)


for c in panel.CLASSES:
    guarded(c)
addon.register()
bpy.app.timers.register(step, first_interval=1.0)
