"""Writing clips of a take as BVH, FBX or glTF binary (``.glb``), and clips of a point take
as C3D or joint-position CSV (the same points, rate and gaps; :mod:`motionlib.io.c3dfile`,
:mod:`motionlib.io.pointcsv`).

BVH is written here (:func:`motionlib.io.bvh.write_bvh`); FBX by Blender's exporter, in the
Blender process of :mod:`motionlib.io.blender`; glTF by Blender only when it is cut from an FBX
original, and otherwise here, without Blender (:mod:`motionlib.io.gltf`, milliseconds a clip):

- a take read from FBX, given its original file, is cut from that file: the same armature (bone
  names, rest orientations, the meshes it deforms) with the animation's frames [start, stop);
- any other take becomes a new armature with the take's joint names, hierarchy and rest offsets,
  each bone's rest orientation the world's (BVH-shaped), keyed on every frame.

Either way a clip of ``stop - start`` frames is ``stop - start`` keys, one per frame at the take's
frame rate, the first at time 0 (so Blender's FBX importer puts it on its first frame, 1, and a
glTF animation starts at 0 s), Y up. Lengths are in metres as :func:`motionlib.io.units.length_unit`
decides the take's unit (an FBX take keeps its declared size when it is human-sized); an FBX
written here declares centimetres, in which :mod:`motionlib.io.fbx` reads it back.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np

from motionlib.errors import CaptureError
from motionlib.io.bvh import write_bvh
from motionlib.io.c3dfile import write_c3d
from motionlib.io.fbx import (
    CENTIMETRES_PER_METRE,
    Z_UP_TO_Y_UP,
    check_fbx_header,
    matrix_to_quaternion,
)
from motionlib.io.gltf import write_glb
from motionlib.io.pointcsv import write_points_csv
from motionlib.io.units import length_unit
from motionlib.kinematics import local_transforms
from motionlib.take import Take, frame_range

FORMATS = ("bvh", "fbx", "glb", "c3d", "csv")
POINT_FORMATS = ("c3d", "csv")
ROTATION_FORMATS = ("bvh", "fbx", "glb")
Y_UP_TO_Z_UP = Z_UP_TO_Y_UP.T


def write_clip(take: Take, out, *, format: str, start: int | None = None,
               stop: int | None = None, original=None, blender=None,
               timeout: float | None = None) -> None:
    """Write frames [start, stop) of ``take`` to the file ``out``.

    Parameters
    ----------
    take : Take
    out : str or PathLike
        The file to write.
    format : {"bvh", "fbx", "glb", "c3d", "csv"}
        C3D and CSV for a point take, the others for a take of joint rotations.
    start, stop : int, optional
        0-based, stop exclusive (default: the whole take).
    original : str or PathLike, optional
        The FBX file an FBX take was read from: the clip is cut from it, keeping its armature.
    blender : motionlib.io.blender.Blender, optional
    timeout : float, optional
        Seconds Blender may take (default: its time limit).

    Raises
    ------
    CaptureError
        Unknown format, a frame range outside the take, Blender failing on the file.
    """
    write_clips(take, [(start, stop, out)], format=format, original=original, blender=blender,
                timeout=timeout)


def write_clips(take: Take, clips, *, format: str, original=None, blender=None,
                timeout: float | None = None) -> None:
    """Write several clips of one take: ``clips`` is a list of ``(start, stop, out)``.

    Like :func:`write_clip`, but an original FBX is imported once for all of them.
    """
    check_export_format(take, format)
    clips = [(*frame_range(take.n_frames, start, stop), os.fspath(out))
             for start, stop, out in clips]
    if format in POINT_FORMATS:
        write = write_c3d if format == "c3d" else write_points_csv
        for start, stop, out in clips:
            write(take, out, start=start, stop=stop)
        return
    if format == "bvh":
        for start, stop, out in clips:
            write_bvh(take, out, start=start, stop=stop)
        return
    if format == "glb" and not (original is not None and take.format == "fbx"):
        _write_glb_clips(take, clips)
        return
    from motionlib.io import blender as blender_module

    blender = blender or blender_module.shared()
    what = f"writing {format.upper()} clips"
    if original is not None and take.format == "fbx":
        check_fbx_header(original)
        unit = length_unit(take)
        blender.request({
            "op": "trim", "path": os.path.abspath(os.fspath(original)),
            "animation": take.animation, "fps": take.fps, "format": format,
            # The armature as the file has it, rescaled when its declared unit is not the one.
            "scale": unit.metres * CENTIMETRES_PER_METRE,
            "clips": [{"start": a, "stop": b, "out": os.path.abspath(o)} for a, b, o in clips],
        }, path=original, what=what, timeout=timeout)
        return
    metres = length_unit(take).metres
    for start, stop, out in clips:
        _write_new_armature(take.slice(start, stop), out, format, blender, timeout, metres)


def check_export_format(take, format: str) -> None:
    """CaptureError unless ``format`` is one a take of this kind is written in: points
    (markers, tracked joints) as C3D or CSV, joint rotations as BVH, FBX or glTF."""
    if format not in FORMATS:
        raise CaptureError(f"unknown export format {format!r}; expected one of "
                           f"{', '.join(FORMATS)}")
    points = getattr(take.skeleton, "point_set", False)
    allowed = POINT_FORMATS if points else ROTATION_FORMATS
    if format not in allowed:
        kind = "a take of points (markers or tracked joints)" if points else \
            "a take of joint rotations"
        raise CaptureError(f"export format {format!r}: {kind} is written as "
                           f"{' or '.join(allowed)}", path=take.path)


def _write_glb_clips(take, clips):
    """glTF of a take that is not cut from an FBX original (no mesh to keep): written here,
    without Blender (:mod:`motionlib.io.gltf`)."""

    metres = length_unit(take).metres
    for start, stop, out in clips:
        write_glb(take.slice(start, stop), out, metres=metres)


def _write_new_armature(take, out, format, blender, timeout, metres):
    meta, arrays = armature_pose(take, metres=metres)
    with tempfile.TemporaryDirectory(prefix="motionlib-export-") as folder:
        pose = os.path.join(folder, "pose.npz")
        np.savez(pose, **arrays)
        blender.request({"op": "write", "in": pose, "meta": meta, "out": os.path.abspath(out),
                         "format": format}, path=take.path or take.name,
                        what=f"writing the {format.upper()} clip", timeout=timeout)


def armature_pose(take: Take, *, metres: float | None = None) -> tuple[dict, dict[str, np.ndarray]]:
    """The take as Blender bones: rest heads, and per frame each bone's local rotation and
    location offset, in Blender's Z-up metres.

    ``metres`` per unit of the take's lengths (default: :func:`~motionlib.io.units.length_unit`).

    Returns
    -------
    meta : dict
        ``name``, ``fps``, ``bones``, ``parents``, ``moving`` (bones with position channels).
    arrays : dict
        ``heads`` (n_bones, 3); ``quaternions`` (n_frames, n_bones, 4) as (w, x, y, z), each
        continuous over time; ``locations`` (n_frames, n_bones, 3).
    """
    sk = take.skeleton
    scale = length_unit(take).metres if metres is None else metres
    rest = np.zeros((sk.n_joints, 3))
    for j in range(sk.n_joints):
        p = sk.parents[j]
        rest[j] = sk.offsets[j] + (rest[p] if p >= 0 else 0.0)
    rotations, translations = local_transforms(take)
    to_z = Y_UP_TO_Z_UP
    R = to_z @ rotations @ to_z.T
    n, J = rotations.shape[:2]
    quats = matrix_to_quaternion(R.reshape(-1, 3, 3)).reshape(n, J, 4)
    flips = np.cumsum(np.sum(quats[1:] * quats[:-1], axis=-1) < 0, axis=0) % 2
    quats[1:][flips.astype(bool)] *= -1
    locations = (translations - sk.offsets[None]) @ to_z.T * scale
    meta = {"name": take.name, "fps": take.fps, "bones": list(sk.names),
            "parents": [int(p) for p in sk.parents],
            "moving": [any(c.endswith("position") for c in ch) for ch in sk.channels]}
    arrays = {"heads": rest @ to_z.T * scale, "quaternions": quats, "locations": locations}
    return meta, arrays
