"""What Blender's own importers make of an exported clip: an oracle for the FBX and glTF files
motionlib writes. Run by an interpreter that has ``bpy``, never imported:

    python -I blender_facts.py CLIP.fbx|CLIP.glb

prints one JSON object: the scene's frame range after import (``frame_start``, ``frame_end``),
the frames of the first and last key of the armature's action and how many keys its curves
hold (``first_key``, ``last_key``, ``keys``), and the figure's height in metres on the first key
(``height``: the vertical extent of its posed bone heads in the world, as Blender shows them).
"""

import json
import sys

import bpy


def main(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if path.endswith(".fbx"):
        bpy.ops.import_scene.fbx(filepath=path)
    else:
        bpy.ops.import_scene.gltf(filepath=path)
    scene = bpy.context.scene
    armature = next(o for o in scene.objects if o.type == "ARMATURE")
    action = armature.animation_data.action
    keys = sorted({round(k.co[0], 3) for c in curves(action) for k in c.keyframe_points})
    scene.frame_set(int(keys[0]))
    z = [(armature.matrix_world @ b.head).z for b in armature.pose.bones]
    print(json.dumps({"frame_start": scene.frame_start, "frame_end": scene.frame_end,
                      "first_key": keys[0], "last_key": keys[-1], "keys": len(keys),
                      "height": max(z) - min(z)}))


def curves(action):
    if getattr(action, "fcurves", None):
        return list(action.fcurves)
    return [c for layer in action.layers for strip in layer.strips
            for bag in strip.channelbags for c in bag.fcurves]


if __name__ == "__main__":
    main(sys.argv[1])
