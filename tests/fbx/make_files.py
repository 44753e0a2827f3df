"""Write the FBX files the tests need that the shared data has not, with Blender itself.

Run by an interpreter that has ``bpy`` (``python -I make_files.py SHARED_FBX_DIR OUT_DIR``),
never imported. Every file is a real Blender FBX export:

- ``mesh_only.fbx``: a cube, no armature;
- ``still_armature.fbx``: an armature with no animation;
- ``two_armatures.fbx``: the Mixamo ``flair`` and ``breakdance_1990`` rigs side by side, each
  with its own animation;
- ``two_actions.fbx``: the ``flair`` rig with two actions (flair, and breakdance's motion);
- ``two_roots.fbx``: an animated armature of two bones, neither the other's parent.
"""

import sys

import bpy


def empty():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def export(path, **options):
    bpy.ops.export_scene.fbx(filepath=path, add_leaf_bones=False, **options)


def armatures():
    return [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]


def main(shared, out):
    empty()
    bpy.ops.mesh.primitive_cube_add()
    export(f"{out}/mesh_only.fbx")

    empty()
    bpy.ops.object.armature_add()
    export(f"{out}/still_armature.fbx", bake_anim=False)

    empty()
    bpy.ops.import_scene.fbx(filepath=f"{shared}/flair.fbx")
    bpy.ops.import_scene.fbx(filepath=f"{shared}/breakdance_1990.fbx")
    first, second = armatures()
    first.name, second.name = "Flair", "Breakdance"
    second.location.x += 2.0
    bpy.context.scene.frame_end = 106
    export(f"{out}/two_armatures.fbx", object_types={"ARMATURE"}, bake_anim_use_all_actions=False,
           bake_anim_use_nla_strips=False)

    empty()
    bpy.ops.import_scene.fbx(filepath=f"{shared}/breakdance_1990.fbx")
    breakdance = armatures()[0].animation_data.action
    breakdance.name = "breakdance"
    breakdance.use_fake_user = True
    bpy.data.objects.remove(armatures()[0])
    bpy.ops.import_scene.fbx(filepath=f"{shared}/flair.fbx")
    rig = armatures()[0]
    rig.animation_data.action.name = "flair"
    rig.animation_data.action.use_fake_user = True
    bpy.context.scene.frame_end = 106
    export(f"{out}/two_actions.fbx", object_types={"ARMATURE"}, bake_anim_use_all_actions=True,
           bake_anim_use_nla_strips=False)

    empty()
    bpy.ops.object.armature_add()
    rig = armatures()[0]
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    second = rig.data.edit_bones.new("Second")
    second.head, second.tail = (1.0, 0.0, 0.0), (1.0, 0.0, 1.0)
    bpy.ops.object.mode_set(mode="OBJECT")
    bone = rig.pose.bones["Bone"]
    bone.keyframe_insert("location", frame=1)
    bone.location.x = 0.5
    bone.keyframe_insert("location", frame=10)
    bpy.context.scene.frame_end = 10
    export(f"{out}/two_roots.fbx", object_types={"ARMATURE"})


if __name__ == "__main__":
    main(*sys.argv[1:3])
