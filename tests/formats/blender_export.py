"""Exports a BVH through Blender as FBX and glTF, for the format tests.

    blender --background --factory-startup --python tests/formats/blender_export.py -- IN.bvh OUTDIR [PREFIX]

Writes OUTDIR/blender.fbx (Y up), OUTDIR/blender_zup.fbx (Z up) and
OUTDIR/blender.glb. PREFIX (e.g. "mixamorig:") is put before every bone name,
as Mixamo's rigs have it. Blender 3.4.1's BVH importer opens its file with
mode 'rU', which Python 3.11 refuses: the mode is given without the 'U' here.
The scene runs at the BVH's rate; FBX curves are not simplified, so every frame
is a key. A small mesh skinned to every bone gives the files a skin and a bind
pose, as a character has.
"""
import builtins
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
bvh, outdir = argv[0], argv[1]
prefix = argv[2] if len(argv) > 2 else ""

_open = builtins.open


def _open_without_u(file, mode="r", *args, **kwargs):
    return _open(file, mode.replace("U", ""), *args, **kwargs)


builtins.open = _open_without_u
bpy.ops.wm.read_factory_settings(use_empty=True)
with _open(bvh) as f:
    text = f.read()
frame_time = float(text.split("Frame Time:")[1].split()[0])
frames = int(text.split("Frames:")[1].split()[0])
fps = round(1.0 / frame_time)
scene = bpy.context.scene
scene.render.fps = fps
scene.render.fps_base = 1.0
# global_scale 0.01: the BVH's centimetres become metres.
bpy.ops.import_anim.bvh(filepath=bvh, global_scale=0.01, frame_start=1, use_fps_scale=False,
                        update_scene_fps=False, update_scene_duration=True, rotate_mode="NATIVE")
builtins.open = _open
scene.frame_start = 1
scene.frame_end = frames
arm = bpy.context.view_layer.objects.active
if prefix:
    for bone in arm.data.bones:
        bone.name = prefix + bone.name

# A skinned mesh, as characters have: a small triangle at the head of every
# bone, weighted to it. It gives the FBX its bind pose (the rest pose: without
# a skin, Blender writes the pose of the current frame as the bones' transforms).
verts, faces = [], []
for bone in arm.data.bones:
    h = arm.matrix_world @ bone.head_local
    k = len(verts)
    verts += [(h.x, h.y, h.z), (h.x + 0.01, h.y, h.z), (h.x, h.y + 0.01, h.z)]
    faces.append((k, k + 1, k + 2))
mesh = bpy.data.meshes.new("skin")
mesh.from_pydata(verts, [], faces)
skin = bpy.data.objects.new("skin", mesh)
scene.collection.objects.link(skin)
for i, bone in enumerate(arm.data.bones):
    group = skin.vertex_groups.new(name=bone.name)
    group.add([3 * i, 3 * i + 1, 3 * i + 2], 1.0, "REPLACE")
skin.parent = arm
skin.modifiers.new("armature", "ARMATURE").object = arm

os.makedirs(outdir, exist_ok=True)
common = dict(use_selection=False, object_types={"ARMATURE", "MESH"}, add_leaf_bones=False, bake_anim=True,
              bake_anim_use_all_actions=False, bake_anim_use_nla_strips=False, bake_anim_simplify_factor=0.0,
              bake_anim_force_startend_keying=True)
bpy.ops.export_scene.fbx(filepath=os.path.join(outdir, "blender.fbx"), axis_forward="-Z", axis_up="Y", **common)
bpy.ops.export_scene.fbx(filepath=os.path.join(outdir, "blender_zup.fbx"), axis_forward="Y", axis_up="Z", **common)
bpy.ops.export_scene.gltf(filepath=os.path.join(outdir, "blender.glb"), export_format="GLB", export_animations=True,
                          export_force_sampling=True, export_frame_range=True)
