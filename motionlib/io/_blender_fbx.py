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
``{"op": "trim", "path": FBX, "animation": NAME|null, "fps": F, "format": "fbx"|"glb",
"scale": S, "clips": [{"start": I, "stop": J, "out": PATH}, ...]}``
    Import the original FBX and export frames [start, stop) of one of its animations, with
    the same armature (bones, rest orientations, meshes), scaled by S.

Every clip written has one key per frame of the clip, the first at time 0: Blender's FBX
importer puts a file's time 0 on its frame 1, and the glTF exporter slides the clip to 0 s.
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
        result = _import(request["path"])
    except RuntimeError as exc:
        raise InputProblem(_import_error(exc, request["path"])) from None
    if "FINISHED" not in result:
        raise InputProblem("Blender's FBX importer gave up on the file (corrupt or truncated?)")
    scene = bpy.context.scene
    armatures = [o for o in scene.objects if o.type == "ARMATURE"]
    if not armatures:
        kinds = sorted({o.type.lower() for o in scene.objects}) or ["nothing"]
        raise InputProblem(f"no armature (skeleton) in the file; it holds {', '.join(kinds)}. "
                           "Export the take with its skeleton and animation")
    arrays, animations = {}, []
    for armature, action, name in _animations(armatures):
        key = f"a{len(animations)}"
        frames, paths, values = _sample(_curves(action, armature), key)
        arrays[f"{key}_frames"] = frames
        arrays[f"{key}_curves"] = values
        animations.append({"key": key, "name": name, "action": action.name,
                           "armature": armature.name, "curves": paths,
                           **_armature_description(armature, arrays, key)})
    if not animations:
        names = ", ".join(repr(a.name) for a in armatures)
        raise InputProblem(f"the armature {names} has no animation (no keyed bones); export "
                           "the take with its animation baked")
    np.savez(request["out"], **arrays)
    render = scene.render
    return {"fps": render.fps / render.fps_base, "animations": animations}


def _import(path):
    """Blender's FBX importer as motionlib uses it: bones as the file has them (no leaf bones
    dropped, no orientation guessed), and no search of the file's folder for textures (a take
    needs none, and a big folder makes the search slow)."""
    import bpy

    return bpy.ops.import_scene.fbx(filepath=path, use_anim=True, ignore_leaf_bones=False,
                                    automatic_bone_orientation=False, use_image_search=False,
                                    use_custom_props=False)


def _import_error(exc, path):
    """Blender's complaint, without the folder the file is stored in (the message names the
    file already). Only binary FBX reaches Blender (``fbx.check_fbx_header``), so its "ASCII
    FBX" is a binary file whose start it could not read: cut short or damaged."""
    text = str(exc).strip().splitlines()
    last = text[-1] if text else type(exc).__name__
    if "ASCII" in str(exc):
        last = "the start of the file does not read as binary FBX"
    last = last.replace(os.path.abspath(path), os.path.basename(path)).replace(
        os.fspath(path), os.path.basename(path))
    return f"Blender's FBX importer could not read the file (corrupt or truncated?): {last}"


def _animations(armatures):
    """(armature, action, name) of every keyed armature animation, in file order.

    The name is the action's without the armature's prefix that Blender's importer adds
    ("Armature|mixamo.com|Layer0" -> "mixamo.com|Layer0"), kept whole when several armatures
    are animated.
    """
    found = [(arm, act) for arm in armatures for act in _actions_of(arm) if _curves(act, arm)]
    several = len({arm.name for arm, _ in found}) > 1
    named = []
    for armature, action in found:
        name, prefix = action.name, armature.name + "|"
        while not several and name.startswith(prefix):
            name = name[len(prefix):]
        named.append((armature, action, name or action.name))
    return named


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
    _import(request["path"])
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
    """A new armature from a take's rest heads and per-frame local poses, exported."""
    import bpy

    meta = request["meta"]
    with np.load(request["in"]) as data:
        heads, quats, locations = data["heads"], data["quaternions"], data["locations"]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    _set_fps(meta["fps"])
    armature = _build_armature(meta["name"], meta["bones"], meta["parents"], heads)
    _key_pose(armature, meta["bones"], quats, locations, meta["moving"])
    n = quats.shape[0]
    bpy.context.scene.frame_start, bpy.context.scene.frame_end = 0, n - 1
    _export(request["out"], request["format"], {"ARMATURE"})
    return {"frames": int(n)}


def op_trim(request):
    """The original FBX again, cut to frames [start, stop) of one animation, once per clip.

    The animation's armature (and the meshes it deforms) are kept, scaled by ``scale`` (its
    declared unit is not always the one its maker meant), every other armature removed; the
    file is imported once for all clips. A baked animation keeps its keys, renumbered 0, 1, …
    (its key times may drift from whole frames by float rounding, as Blender's BVH round trip
    leaves them); any other is shifted so that the clip's first frame is at 0 and sampled by
    the exporter on the scene frames of the range. The FBX exporter writes key times as they
    are, so starting at 0 is what makes the clip start at time 0.
    """
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    _import(request["path"])
    scene = bpy.context.scene
    armatures = [o for o in scene.objects if o.type == "ARMATURE"]
    found = [(arm, act) for arm, act, name in _animations(armatures)
             if request["animation"] in (None, name)]
    if not found:
        raise InputProblem(f"no animation {request['animation']!r} in the file any more")
    armature, action = found[0]
    for other in [o for o in armatures if o is not armature]:
        for child in list(other.children_recursive) + [other]:
            bpy.data.objects.remove(child)
    scale = float(request.get("scale", 1.0))
    _rescale(armature, scale)
    _set_fps(request["fps"])
    curves = _curves(action, armature)
    counts = {len(c.keyframe_points) for c in curves}
    frames, _, _ = _sample(curves, None)
    for clip in request["clips"]:
        start, stop = int(clip["start"]), int(clip["stop"])
        cut = action.copy()
        _bind(armature, cut)
        if len(counts) == 1 and stop <= next(iter(counts)):  # baked: one key per frame
            for c in _curves(cut, armature):
                _renumber(c, start, stop)
            scene.frame_start, scene.frame_end = 0, stop - start - 1
        else:
            first = int(round(frames[start]))
            for c in _curves(cut, armature):
                _shift(c, -first)
            scene.frame_start, scene.frame_end = 0, int(round(frames[stop - 1])) - first
        _rescale_keys(_curves(cut, armature), scale)
        _export(clip["out"], request["format"], {"ARMATURE", "MESH"})
        _bind(armature, action)
        bpy.data.actions.remove(cut)
    return {"clips": len(request["clips"])}


def _bind(armature, action):
    armature.animation_data.action = action
    if hasattr(armature.animation_data, "action_slot") and action.slots:
        armature.animation_data.action_slot = action.slots[0]


def _renumber(fcurve, start, stop):
    co = np.empty(2 * len(fcurve.keyframe_points))
    fcurve.keyframe_points.foreach_get("co", co)
    values = co[1::2][start:stop].copy()
    fcurve.keyframe_points.clear()
    frames = np.arange(len(values), dtype=np.float64)
    _set_keys(fcurve, frames, values)


def _shift(fcurve, frames):
    """Move every key of ``fcurve`` (and its handles) by ``frames``."""
    points = fcurve.keyframe_points
    for prop in ("co", "handle_left", "handle_right"):
        xy = np.empty(2 * len(points))
        points.foreach_get(prop, xy)
        xy[0::2] += frames
        points.foreach_set(prop, xy)
    fcurve.update()


def _rescale(armature, scale):
    """Scale the armature, and with it the meshes it deforms, about the world's origin."""
    if scale != 1.0:
        armature.scale = armature.scale * scale
        armature.location = armature.location * scale


def _rescale_keys(curves, scale):
    """Scale the keyed location and scale of the armature object itself (FBX importers key
    them with the bones), which would otherwise undo :func:`_rescale` on every frame."""
    if scale == 1.0:
        return
    for fcurve in curves:
        if fcurve.data_path not in ("location", "scale"):
            continue
        points = fcurve.keyframe_points
        for prop in ("co", "handle_left", "handle_right"):
            xy = np.empty(2 * len(points))
            points.foreach_get(prop, xy)
            xy[1::2] *= scale
            points.foreach_set(prop, xy)
        fcurve.update()


def _set_fps(fps):
    import bpy

    render = bpy.context.scene.render
    fps = float(fps)
    render.fps = max(1, round(fps))
    render.fps_base = render.fps / fps


def _export(out, fmt, object_types):
    """Write the scene's armature (and ``object_types``) over the scene's frame range, the
    pose sampled on every frame (for glTF, twice as fast as converting keys, and exact)."""
    import bpy

    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    if fmt == "fbx":
        bpy.ops.export_scene.fbx(filepath=out, use_selection=False, object_types=object_types,
                                 add_leaf_bones=False, bake_anim=True,
                                 bake_anim_use_all_actions=False, bake_anim_use_nla_strips=False,
                                 bake_anim_simplify_factor=0.0,
                                 bake_anim_force_startend_keying=True)
    elif fmt == "glb":
        # The active action only (the default writes every action of the file).
        bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_animations=True,
                                  export_animation_mode="ACTIVE_ACTIONS",
                                  export_force_sampling=True, export_frame_range=True,
                                  export_anim_single_armature=True, export_yup=True,
                                  export_optimize_animation_size=False,
                                  export_anim_slide_to_zero=True)  # clip time starts at 0
    else:
        raise InputProblem(f"unknown export format {fmt!r}; expected fbx or glb")


def _build_armature(name, bones, parents, heads):
    """An armature whose bones sit at ``heads`` (Blender world, Z up), each with the identity
    as its rest orientation (tail straight along +Y, no roll): a BVH-shaped skeleton, whose
    pose rotations are then the take's local rotations as they are."""
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
        bone.tail = heads[i] + np.array([0.0, length, 0.0])
        bone.roll = 0.0
        if parents[i] >= 0:
            bone.parent = edit[parents[i]]
        edit.append(bone)
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def _key_pose(armature, bones, quats, locations, moving):
    """Key every bone's rotation (quaternion, w x y z) and the location of the bones that move
    (the root; any bone whose distance to its parent changes) on frames 0…F-1."""
    import bpy

    frames = np.arange(quats.shape[0], dtype=np.float64)
    armature.animation_data_create()
    action = bpy.data.actions.new(armature.name)
    armature.animation_data.action = action
    for b, bone_name in enumerate(bones):
        armature.pose.bones[bone_name].rotation_mode = "QUATERNION"
        path = f'pose.bones["{bone_name}"]'
        for k in range(4):
            _key_curve(action, f"{path}.rotation_quaternion", k, frames, quats[:, b, k],
                       bone_name)
        if moving[b]:
            for k in range(3):
                _key_curve(action, f"{path}.location", k, frames, locations[:, b, k], bone_name)
    if hasattr(armature.animation_data, "action_slot") and action.slots:
        # Blender 4.4+: curves made through the legacy API sit in a slot nobody is bound to.
        armature.animation_data.action_slot = action.slots[0]


def _key_curve(action, path, index, frames, values, group):
    _set_keys(action.fcurves.new(path, index=index, action_group=group), frames, values)


def _set_keys(fcurve, frames, values):
    fcurve.keyframe_points.add(len(frames))
    co = np.empty(2 * len(frames))
    co[0::2], co[1::2] = frames, values
    fcurve.keyframe_points.foreach_set("co", co)
    # LINEAR: keyed on every frame, nothing to smooth between keys.
    fcurve.keyframe_points.foreach_set("interpolation", np.full(len(frames), 2, np.int32))
    fcurve.update()


OPS = {"read": op_read, "write": op_write, "trim": op_trim, "evaluate": op_evaluate,
       "ping": op_ping}

if __name__ == "__main__":
    main()
