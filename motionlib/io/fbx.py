"""Reading FBX takes, through Blender's FBX importer running in its own process.

Blender (``bpy``) imports the file and hands back each armature animation raw: bone rest
matrices, parents and the F-curves sampled on the animation's frames (see ``_blender_fbx.py``).
Here that becomes a BVH-shaped :class:`~motionlib.take.Take`:

- joints are the armature's bones (names as in the file), each at its head, offsets being the
  rest-pose head differences in the world frame, so every joint's rest orientation is the world's;
- rotations are each bone's world rotation relative to its parent's, with its rest orientation
  taken out, as Euler ZYX degrees; the root, and any bone whose distance to its parent changes,
  gets position channels;
- lengths in centimetres (FBX's own unit), Y up (Blender's Z-up world turned back, as its FBX
  exporter does), the frame rate of the file, one frame per key of a baked animation.

A file with several animations (several actions, or several armatures) gives one take each, in
file order, named ``<file stem>#<animation>``.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from motionlib.errors import CaptureError
from motionlib.io.bvh import _snap_fps, detect_rest_pose
from motionlib.kinematics import euler_to_matrix, matrix_to_euler_zyx
from motionlib.skeleton import Skeleton
from motionlib.take import Take

BINARY_MAGIC = b"Kaydara FBX Binary  \x00"
CENTIMETRES_PER_METRE = 100.0
# Blender's Z-up world to Y up: (x, y, z) -> (x, z, -y).
Z_UP_TO_Y_UP = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])
# Rotations read back through Blender's float32 matrices are this close (degrees) to what was
# written: a rest-pose frame of whole degrees comes back within it (the 13_29 copy: 4e-5).
ROTATION_TOLERANCE_DEG = 1e-3
# A bone whose head strays from where its rest offset puts it by more than this share of the
# skeleton's size gets position channels (Blender computes in float32: ~1e-7 is noise).
MOVING_BONE_SHARE = 1e-5


def check_fbx_header(path) -> None:
    """Refuse files that are not binary FBX before starting Blender on them."""
    with open(path, "rb") as handle:
        head = handle.read(64)
    if head.startswith(BINARY_MAGIC):
        return
    if b"FBX" in head and (head.lstrip().startswith(b";") or b"FBXHeaderExtension" in head):
        raise CaptureError("ASCII FBX is not supported (Blender reads binary FBX only); export "
                           "the take again as binary FBX", path=path)
    raise CaptureError("not an FBX file (no binary FBX header); upload the .fbx your capture "
                       "software exported", path=path)


def read_fbx_raw(path, *, blender=None, timeout=None):
    """Blender's raw dump of every armature animation: (description, arrays)."""
    from motionlib.io import blender as blender_module

    path = os.fspath(path)
    check_fbx_header(path)
    blender = blender or blender_module.shared()
    with tempfile.TemporaryDirectory(prefix="motionlib-fbx-") as folder:
        out = os.path.join(folder, "animations.npz")
        reply = blender.request({"op": "read", "path": os.path.abspath(path), "out": out},
                                path=path, what="reading the FBX", timeout=timeout)
        with np.load(out, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
    return reply, arrays


def read_fbx_all(path, *, blender=None, timeout=None) -> list[Take]:
    """Every armature animation of an FBX file, one take each.

    Parameters
    ----------
    path : str or PathLike
    blender : motionlib.io.blender.Blender, optional
        The Blender process to use (default: this process's shared one).
    timeout : float, optional
        Seconds Blender may take before it is stopped (default 300).

    Returns
    -------
    list of Take
        In file order; ``take.animation`` names each one, and ``take.name`` is the file stem,
        followed by ``#<animation>`` when the file has several.

    Raises
    ------
    CaptureError
        Not a binary FBX, no armature, no animation, a file Blender cannot read, Blender
        crashing or hanging on it; the message names the file and the problem.
    """
    reply, arrays = read_fbx_raw(path, blender=blender, timeout=timeout)
    animations = reply["animations"]
    single = len(animations) == 1
    return [_take(path, a, a["name"], arrays, reply["fps"], single) for a in animations]


def read_fbx(path, *, animation: str | int | None = None, blender=None, timeout=None) -> Take:
    """One animation of an FBX file: the first, or the one named (or numbered) ``animation``.

    See :func:`read_fbx_all`; an unknown ``animation`` is a CaptureError listing the ones there.
    """
    takes = read_fbx_all(path, blender=blender, timeout=timeout)
    return pick_animation(takes, animation, path)


def pick_animation(takes: list[Take], animation, path) -> Take:
    if animation is None:
        return takes[0]
    if isinstance(animation, int):
        if 0 <= animation < len(takes):
            return takes[animation]
    else:
        for take in takes:
            if take.animation == animation:
                return take
    there = ", ".join(repr(t.animation) for t in takes)
    raise CaptureError(f"no animation {animation!r}; the file has {there}", path=path)


def _take(path, animation, name, arrays, scene_fps, single) -> Take:
    roots = [b for b, p in zip(animation["bones"], animation["parents"], strict=True) if p < 0]
    if len(roots) != 1:
        raise CaptureError(f"the armature {animation['armature']!r} has {len(roots)} root bones "
                           f"({', '.join(roots[:5])}); a take needs one skeleton: parent them "
                           "under one bone before exporting", path=path)
    key = animation["key"]
    frames = arrays[f"{key}_frames"]
    world = world_matrices(animation, arrays[f"{key}_curves"], arrays[f"{key}_rest"],
                           arrays[f"{key}_object_prefix"])
    rest_world = arrays[f"{key}_object_prefix"] @ _object_basis_static(animation) @ \
        arrays[f"{key}_rest"]
    skeleton, channels = bvh_shape(animation["bones"], animation["parents"], world, rest_world)
    step = float(np.median(np.diff(frames))) if len(frames) > 1 else 1.0
    frame_time = step / scene_fps
    stem = Path(path).stem
    return Take(name=stem if single else f"{stem}#{name}", format="fbx",
                fps=_snap_fps(frame_time), frame_time=frame_time, channels=channels,
                skeleton=skeleton,
                rest_pose_frame=detect_rest_pose(skeleton, channels, atol=ROTATION_TOLERANCE_DEG),
                path=os.fspath(path), animation=name)


# --- Blender's pose evaluation ----------------------------------------------------------------

def world_matrices(animation, curves, rest, object_prefix) -> np.ndarray:
    """Each bone's world matrix on each frame, as Blender evaluates an armature pose.

    ``pose(b) = pose(parent) @ rest(parent)^-1 @ rest(b) @ basis(b)`` (``rest(b) @ basis(b)``
    for a root), ``basis = T(location) @ R(rotation) @ S(scale)`` from the bone's F-curves
    (unkeyed channels at rest), and world = object matrix @ pose.

    Returns
    -------
    ndarray, shape (n_frames, n_bones, 4, 4)
    """
    n_frames = curves.shape[1]
    channels = _channel_table(animation["curves"], curves)
    obj = _object_matrices(animation, channels, n_frames)
    world = np.empty((n_frames, len(animation["bones"]), 4, 4))
    pose = np.empty_like(world)
    for b, (name, parent) in enumerate(zip(animation["bones"], animation["parents"], strict=True)):
        bone = f'pose.bones["{name}"].'
        basis = _basis(channels, bone, animation["rotation_modes"][b], n_frames)
        if parent < 0:
            pose[:, b] = rest[b] @ basis
        else:
            pose[:, b] = pose[:, parent] @ (np.linalg.inv(rest[parent]) @ rest[b]) @ basis
        world[:, b] = object_prefix @ obj @ pose[:, b]
    return world


def _channel_table(paths, curves) -> dict[tuple[str, int], np.ndarray]:
    return {(p, int(i)): curves[k] for k, (p, i) in enumerate(paths)}


def _values(channels, path, defaults, n_frames) -> np.ndarray:
    """(n_frames, len(defaults)) of an animated property, unkeyed components at their default."""
    out = np.empty((n_frames, len(defaults)))
    for i, d in enumerate(defaults):
        out[:, i] = channels.get((path, i), d)
    return out


def _basis(channels, prefix, mode, n_frames, static=None) -> np.ndarray:
    """T @ R @ S per frame, shape (n_frames, 4, 4)."""
    static = static or {"location": (0, 0, 0), "rotation_quaternion": (1, 0, 0, 0),
                        "rotation_euler": (0, 0, 0), "scale": (1, 1, 1)}
    location = _values(channels, prefix + "location", static["location"], n_frames)
    scale = _values(channels, prefix + "scale", static["scale"], n_frames)
    if mode == "QUATERNION":
        q = _values(channels, prefix + "rotation_quaternion", static["rotation_quaternion"],
                    n_frames)
        rotation = quaternion_to_matrix(q)
    elif mode == "AXIS_ANGLE":
        raise CaptureError("bones rotated in axis-angle mode are not supported; bake the "
                           "animation to quaternions or Euler angles")
    else:
        e = _values(channels, prefix + "rotation_euler", static["rotation_euler"], n_frames)
        # Blender's "XYZ" applies X first: R = Rz @ Ry @ Rx, motionlib's order "ZYX".
        order = mode[::-1]
        columns = ["XYZ".index(axis) for axis in order]
        rotation = euler_to_matrix(np.rad2deg(e[:, columns]), order)
    m = np.zeros((n_frames, 4, 4))
    m[:, :3, :3] = rotation * scale[:, None, :]
    m[:, :3, 3] = location
    m[:, 3, 3] = 1.0
    return m


def _object_matrices(animation, channels, n_frames) -> np.ndarray:
    """The armature object's own (possibly keyed) transform, shape (n_frames, 4, 4)."""
    static = animation["object"]
    return _basis(channels, "", static["rotation_mode"], n_frames, static)


def _object_basis_static(animation) -> np.ndarray:
    return _basis({}, "", animation["object"]["rotation_mode"], 1, animation["object"])[0]


def quaternion_to_matrix(q: np.ndarray) -> np.ndarray:
    """(n, 4) quaternions (w, x, y, z), normalised first as Blender does -> (n, 3, 3)."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


def matrix_to_quaternion(R: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations -> (n, 4) unit quaternions (w, x, y, z) with w >= 0."""
    R = np.asarray(R, dtype=np.float64)
    w = np.sqrt(np.maximum(0.0, 1 + R[:, 0, 0] + R[:, 1, 1] + R[:, 2, 2])) / 2
    x = np.sqrt(np.maximum(0.0, 1 + R[:, 0, 0] - R[:, 1, 1] - R[:, 2, 2])) / 2
    y = np.sqrt(np.maximum(0.0, 1 - R[:, 0, 0] + R[:, 1, 1] - R[:, 2, 2])) / 2
    z = np.sqrt(np.maximum(0.0, 1 - R[:, 0, 0] - R[:, 1, 1] + R[:, 2, 2])) / 2
    x = np.copysign(x, R[:, 2, 1] - R[:, 1, 2])
    y = np.copysign(y, R[:, 0, 2] - R[:, 2, 0])
    z = np.copysign(z, R[:, 1, 0] - R[:, 0, 1])
    q = np.stack([w, x, y, z], axis=1)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


# --- to the BVH shape ---------------------------------------------------------------------------

def _to_y_up_cm(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(positions (..., 3) in cm, rotations (..., 3, 3) orthonormal) of Blender world matrices."""
    positions = m[..., :3, 3] @ Z_UP_TO_Y_UP.T * CENTIMETRES_PER_METRE
    linear = Z_UP_TO_Y_UP @ m[..., :3, :3]
    # Object and bone scale (Mixamo rigs: 0.01) leave the axes scaled; keep their directions.
    rotations = linear / np.linalg.norm(linear, axis=-2, keepdims=True)
    return positions, rotations


def bvh_shape(names, parents, world, rest_world) -> tuple[Skeleton, np.ndarray]:
    """A BVH-shaped skeleton and its channels from bone world matrices.

    Parameters
    ----------
    names : list of str
    parents : list of int
        Blender's bone order (parents first).
    world : ndarray, shape (n_frames, n_bones, 4, 4)
    rest_world : ndarray, shape (n_bones, 4, 4)

    Returns
    -------
    skeleton : Skeleton
        Offsets in cm, Y up; ZYX rotation channels on every joint, positions on the root and on
        joints whose distance to their parent changes.
    channels : ndarray, shape (n_frames, n_channels)
    """
    order = _depth_first(parents)
    names = [names[j] for j in order]
    remap = {old: new for new, old in enumerate(order)}
    parents = np.array([remap[parents[j]] if parents[j] >= 0 else -1 for j in order])
    positions, rotations = _to_y_up_cm(world[:, order])
    rest_positions, rest_rotations = _to_y_up_cm(rest_world[order])
    # Joint frames that are the world's at rest: G = R_world @ R_rest^T.
    G = rotations @ np.swapaxes(rest_rotations, -1, -2)[None]
    offsets = np.zeros_like(rest_positions)
    has_parent = parents >= 0
    offsets[has_parent] = rest_positions[has_parent] - rest_positions[parents[has_parent]]
    columns, layout = [], []
    tolerance = MOVING_BONE_SHARE * max(float(np.ptp(rest_positions, axis=0).max()), 1.0)
    for j in range(len(names)):
        p = parents[j]
        if p < 0:
            local_pos, local_rot = positions[:, j], G[:, j]
        else:
            parent_T = np.swapaxes(G[:, p], -1, -2)
            local_pos = np.einsum("fij,fj->fi", parent_T, positions[:, j] - positions[:, p])
            local_rot = parent_T @ G[:, j]
        moves = p < 0 or np.abs(local_pos - offsets[j]).max() > tolerance
        channel_names = ("Xposition", "Yposition", "Zposition") if moves else ()
        if moves:
            columns.append(local_pos)
        columns.append(matrix_to_euler_zyx(local_rot))
        layout.append(channel_names + ("Zrotation", "Yrotation", "Xrotation"))
    skeleton = Skeleton(names=names, parents=parents, offsets=offsets, channels=layout,
                        rotation_orders=["ZYX"] * len(names))
    return skeleton, np.ascontiguousarray(np.concatenate(columns, axis=1))


def _depth_first(parents) -> list[int]:
    children = {}
    for j, p in enumerate(parents):
        children.setdefault(p, []).append(j)
    order, stack = [], list(reversed(children.get(-1, [])))
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(children.get(j, [])))
    return order
