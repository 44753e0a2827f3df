"""Blender side of motionlib's FBX reading and writing: run by Blender's Python, never imported.

This script runs in its own process under an interpreter that has Blender as a module (``bpy``,
GPL; see ``motionlib.io.blender``), so neither motionlib nor the web server ever imports Blender.
It serves requests one per line on stdin, a JSON object each, and answers each with one JSON line
on the file descriptor the parent passed as ``--reply-fd``; Blender's own chatter goes to stderr.
Blender's start-up is paid once per process, not per file.

Requests:

``{"op": "read", "path": FBX, "out": NPZ}``
    Import the FBX into an empty scene and dump every armature animation, raw: the armature's
    bones (rest matrices, parents) and each animation's F-curves sampled on its frames. The
    numbers go to ``out`` (``.npz``), the description in the reply. The arithmetic that turns
    them into a take is motionlib's (``motionlib.io.fbx``).
``{"op": "write", "in": NPZ, "meta": {...}, "out": PATH, "format": "fbx"|"glb"}``
    Build an armature from rest heads and per-frame bone rotations/positions, key it, and export
    it as binary FBX or glTF binary.
``{"op": "evaluate", "path": FBX, "frames": [...]}``
    Blender's own pose evaluation of the first armature's assigned action: each bone's head in
    world coordinates on the given scene frames (an oracle for motionlib's pose arithmetic).
``{"op": "ping"}``
    Answer ``{"ok": true}`` once Blender is loaded.

A problem with the input is answered ``{"ok": false, "error": "..."}``; the process lives on.
"""

import argparse
import json
import os
import sys
import traceback

import numpy as np


class InputProblem(Exception):
    """The file cannot be read as an animated armature; the message says why."""


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--reply-fd", type=int, required=True)
    args = parser.parse_args()
    reply = os.fdopen(args.reply_fd, "w", buffering=1)
    _exit_with_parent()
    os.dup2(2, 1)  # Blender and its add-ons print to stdout; keep that off the reply channel
    sys.stdout = sys.stderr
    import bpy  # noqa: F401  (the slow part, once)

    for line in sys.stdin:
        request = json.loads(line)
        try:
            answer = {"ok": True, **OPS[request["op"]](request)}
        except InputProblem as exc:
            answer = {"ok": False, "error": str(exc)}
        except Exception as exc:  # Blender's importer raises anything on a bad file
            traceback.print_exc()
            answer = {"ok": False, "error": f"{type(exc).__name__}: {exc}", "internal": True}
        reply.write(json.dumps(answer) + "\n")


def _exit_with_parent():
    """End when the process that started us is gone (killed by a time limit, say) instead of
    living on as an orphan, possibly stuck in a file that made Blender hang."""
    import threading
    import time

    parent = os.getppid()

    def watch():
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(3)

    threading.Thread(target=watch, daemon=True).start()


def op_ping(request):
    import bpy

    return {"version": bpy.app.version_string}


# --- reading ------------------------------------------------------------------------------

def op_read(request):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    try:
        result = bpy.ops.import_scene.fbx(filepath=request["path"], use_anim=True,
                                          ignore_leaf_bones=False, automatic_bone_orientation=False)
    except RuntimeError as exc:
        raise InputProblem(_import_error(exc)) from None
    if "FINISHED" not in result:
        raise InputProblem("Blender's FBX importer gave up on the file (corrupt or truncated?)")
    scene = bpy.context.scene
    armatures = [o for o in scene.objects if o.type == "ARMATURE"]
    if not armatures:
        kinds = sorted({o.type.lower() for o in scene.objects}) or ["nothing"]
        raise InputProblem(f"no armature (skeleton) in the file; it holds {', '.join(kinds)}. "
                           "Export the take with its skeleton and animation")
    arrays, animations = {}, []
    for armature in armatures:
        for action in _actions_of(armature):
            key = f"a{len(animations)}"
            frames, paths, values = _sample(_curves(action, armature), key)
            if frames is None:
                continue
            arrays[f"{key}_frames"] = frames
            arrays[f"{key}_curves"] = values
            animations.append({"key": key, "action": action.name, "armature": armature.name,
                               "curves": paths, **_armature_description(armature, arrays, key)})
    if not animations:
        names = ", ".join(repr(a.name) for a in armatures)
        raise InputProblem(f"the armature {names} has no animation (no keyed bones); export "
                           "the take with its animation baked")
    np.savez(request["out"], **arrays)
    render = scene.render
    return {"fps": render.fps / render.fps_base, "animations": animations}


def _import_error(exc):
    text = str(exc).strip().splitlines()
    last = text[-1] if text else type(exc).__name__
    if "ASCII" in str(exc):
        return ("ASCII FBX is not supported (Blender reads binary FBX only); export the take "
                "again as binary FBX")
    return f"Blender's FBX importer could not read the file (corrupt or truncated?): {last}"


def _actions_of(armature):
    """Actions that key this armature's bones, the assigned one first."""
    import bpy

    bones = {b.name for b in armature.data.bones}
    assigned = armature.animation_data.action if armature.animation_data else None
    found = [assigned] if assigned is not None else []
    for action in bpy.data.actions:
        if action is assigned:
            continue
        # The FBX importer names actions "<object>|<stack>[|<layer>]".
        if action.name.split("|", 1)[0] == armature.name and _keys_bones(action, bones):
            found.append(action)
    return [a for a in found if _keys_bones(a, bones)]


def _keys_bones(action, bones):
    for fcurve in _all_curves(action):
        if fcurve.data_path.startswith('pose.bones["'):
            return fcurve.data_path.split('"')[1] in bones
    return False


def _all_curves(action):
    curves = list(action.fcurves) if hasattr(action, "fcurves") else []
    if curves:
        return curves
    # Blender 4.4+ slotted actions keep curves in channel bags.
    for layer in getattr(action, "layers", []):
        for strip in layer.strips:
            for bag in getattr(strip, "channelbags", []):
                curves.extend(bag.fcurves)
    return curves


def _curves(action, armature):
    return [c for c in _all_curves(action) if len(c.keyframe_points)]


def _sample(curves, key):
    """(frames (F,), [[data_path, index]…], values (C, F)) or (None…) without keys.

    A baked animation (every curve keyed on the same frames, as motion-capture FBX is) is read
    from its keys as they are; otherwise each curve is evaluated on every scene frame between
    the first and the last key.
    """
    if not curves:
        return None, None, None
    keys = []
    for c in curves:
        co = np.empty(2 * len(c.keyframe_points))
        c.keyframe_points.foreach_get("co", co)
        keys.append(co.reshape(-1, 2))
    first = keys[0][:, 0]
    if all(len(k) == len(first) and np.allclose(k[:, 0], first, atol=1e-4) for k in keys):
        frames, values = first, np.stack([k[:, 1] for k in keys])
    else:
        lo = min(k[0, 0] for k in keys)
        hi = max(k[-1, 0] for k in keys)
        frames = np.arange(np.floor(lo), np.ceil(hi) + 0.5)
        values = np.array([[c.evaluate(f) for f in frames] for c in curves])
    paths = [[c.data_path, c.array_index] for c in curves]
    return frames.astype(np.float64), paths, values.astype(np.float64)


def _armature_description(armature, arrays, key):
    bones = list(armature.data.bones)
    index = {b.name: i for i, b in enumerate(bones)}
    arrays[f"{key}_rest"] = np.array([np.array(b.matrix_local) for b in bones])
    # The object's transform without its own (possibly keyed) basis: parents, parent inverse.
    prefix = armature.matrix_world @ armature.matrix_basis.inverted()
    arrays[f"{key}_object_prefix"] = np.array(prefix)
    pose = armature.pose.bones
    return {
        "bones": [b.name for b in bones],
        "parents": [index[b.parent.name] if b.parent else -1 for b in bones],
        "rotation_modes": [pose[b.name].rotation_mode for b in bones],
        "object": {"location": list(armature.location),
                   "rotation_mode": armature.rotation_mode,
                   "rotation_euler": list(armature.rotation_euler),
                   "rotation_quaternion": list(armature.rotation_quaternion),
                   "scale": list(armature.scale)},
    }


def op_evaluate(request):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.fbx(filepath=request["path"], use_anim=True, ignore_leaf_bones=False,
                             automatic_bone_orientation=False)
    scene = bpy.context.scene
    armature = next(o for o in scene.objects if o.type == "ARMATURE")
    heads = []
    for frame in request["frames"]:
        whole = int(np.floor(frame))
        scene.frame_set(whole, subframe=float(frame - whole))
        heads.append([list(armature.matrix_world @ b.head) for b in armature.pose.bones])
    return {"bones": [b.name for b in armature.pose.bones], "heads": heads}


# --- writing ------------------------------------------------------------------------------

def op_write(request):
    import bpy

    meta = request["meta"]
    with np.load(request["in"]) as data:
        heads, quats, root = data["heads"], data["quaternions"], data["root"]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    fps = float(meta["fps"])
    scene.render.fps = max(1, round(fps))
    scene.render.fps_base = scene.render.fps / fps
    armature = _build_armature(meta["name"], meta["bones"], meta["parents"], heads)
    _key_pose(armature, meta["bones"], meta["parents"], heads, quats, root)
    n = quats.shape[0]
    scene.frame_start, scene.frame_end = 1, n
    os.makedirs(os.path.dirname(os.path.abspath(request["out"])), exist_ok=True)
    if request["format"] == "fbx":
        bpy.ops.export_scene.fbx(filepath=request["out"], use_selection=False,
                                 object_types={"ARMATURE"}, add_leaf_bones=False,
                                 bake_anim=True, bake_anim_use_all_actions=False,
                                 bake_anim_use_nla_strips=False, bake_anim_simplify_factor=0.0,
                                 bake_anim_force_startend_keying=True)
    else:
        bpy.ops.export_scene.gltf(filepath=request["out"], export_format="GLB",
                                  export_animations=True, export_force_sampling=True,
                                  export_frame_range=True, export_yup=True)
    return {"frames": int(n)}


def _build_armature(name, bones, parents, heads):
    """An armature whose bones sit at ``heads`` (Blender world, Z up) with identity rest
    orientation's Y along the bone where possible; every bone has a tail."""
    import bpy

    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    edit = []
    length = max(float(np.ptp(heads[:, 2])), 1e-3) * 0.05
    for i, bone_name in enumerate(bones):
        bone = data.edit_bones.new(bone_name)
        bone.head = heads[i]
        # Rest frame = world frame (a BVH-shaped skeleton): tail straight up +Y, no roll, so
        # the bone's rest matrix is the identity rotation and pose rotations are world ones.
        bone.tail = heads[i] + np.array([0.0, length, 0.0])
        bone.roll = 0.0
        if parents[i] >= 0:
            bone.parent = edit[parents[i]]
        edit.append(bone)
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def _key_pose(armature, bones, parents, heads, quats, root):
    """Key every bone's rotation (local, quaternion) and the root bone's location per frame.

    ``quats`` (F, B, 4) (w, x, y, z) are each bone's rotation relative to its parent, in the
    world frame of the rest pose; with rest matrices of identity rotation (see
    ``_build_armature``) they are exactly the bones' pose rotations. ``root`` (F, 3) is the
    root head's position.
    """
    n = quats.shape[0]
    frames = np.arange(1, n + 1, dtype=np.float64)
    armature.animation_data_create()
    action = bpy_new_action(armature.name)
    armature.animation_data.action = action
    for b, bone_name in enumerate(bones):
        pose_bone = armature.pose.bones[bone_name]
        pose_bone.rotation_mode = "QUATERNION"
        path = f'pose.bones["{bone_name}"].rotation_quaternion'
        for k in range(4):
            _key_curve(action, path, k, frames, quats[:, b, k], group=bone_name)
        if parents[b] < 0:
            path = f'pose.bones["{bone_name}"].location'
            offset = root - heads[b]
            for k in range(3):
                _key_curve(action, path, k, frames, offset[:, k], group=bone_name)


def bpy_new_action(name):
    import bpy

    return bpy.data.actions.new(name)


def _key_curve(action, path, index, frames, values, group):
    fcurve = action.fcurves.new(path, index=index, action_group=group)
    fcurve.keyframe_points.add(len(frames))
    co = np.empty(2 * len(frames))
    co[0::2], co[1::2] = frames, values
    fcurve.keyframe_points.foreach_set("co", co)
    interpolation = np.full(len(frames), 2, dtype=np.int32)  # LINEAR (keyed on every frame)
    fcurve.keyframe_points.foreach_set("interpolation", interpolation)
    fcurve.update()


OPS = {"read": op_read, "write": op_write, "evaluate": op_evaluate, "ping": op_ping}

if __name__ == "__main__":
    main()
