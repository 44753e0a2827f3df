"""Joint positions of a glTF animation as Blender's glTF importer poses them: an oracle for the
.glb files motionlib writes. Run by an interpreter that has ``bpy``, never imported:

    python -I gltf_heads.py CLIP.glb FPS FRAME [FRAME …]

prints ``{"names": [...], "heads": [[[x, y, z], …], …]}`` (Y up, the file's metres), one entry
per clip frame asked for (0-based, at FPS).
"""

import json
import sys

import bpy


def main(path, fps, frames):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    scene = bpy.context.scene
    armature = next(o for o in scene.objects if o.type == "ARMATURE")
    first = armature.animation_data.action.frame_range[0]
    heads = []
    for frame in frames:
        at = first + frame * (scene.render.fps / scene.render.fps_base) / fps
        scene.frame_set(int(at), subframe=at - int(at))
        # Blender's Z up back to glTF's Y up: (x, y, z) -> (x, z, -y).
        heads.append([[h.x, h.z, -h.y] for h in (armature.matrix_world @ b.head
                                                 for b in armature.pose.bones)])
    print(json.dumps({"names": [b.name for b in armature.pose.bones], "heads": heads}))


if __name__ == "__main__":
    main(sys.argv[1], float(sys.argv[2]), [int(f) for f in sys.argv[3:]])
