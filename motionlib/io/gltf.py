"""Writing a clip of a take of joint rotations as glTF binary (``.glb``) without Blender: the
JSON and one binary buffer built with numpy, in milliseconds instead of a Blender round trip.

What it writes matches what Blender's glTF exporter writes for a take without a mesh
(:mod:`motionlib.io.export`), where it matters to a reader of the file:

- one node per joint, named as the take's joint, under one node named as the take (the
  armature); the joints are the ``joints`` of one skin (no mesh uses it), so Blender's importer
  makes them an armature and three.js's GLTFLoader makes them bones;
- each joint's rest translation is its offset from its parent, in metres
  (:func:`motionlib.io.units.length_unit`), Y up as the take (glTF's axes);
- one animation, ``Animation``, keyed on every frame of the clip at the take's frame rate, the
  first at 0 s, LINEAR: every joint's rotation (a unit quaternion, continuous in time) and the
  translation of the joints that have position channels (the root).

Rest orientations are the world's (BVH-shaped), so a joint's animated rotation is the take's
local rotation as it is, and each joint's world position is motionlib's forward kinematics.
"""

from __future__ import annotations

import json
import os
import struct

import numpy as np

from motionlib.io.fbx import matrix_to_quaternion
from motionlib.kinematics import local_transforms
from motionlib.take import Take

FLOAT = 5126  # glTF componentType: 32-bit float
GLB_MAGIC, GLB_VERSION = b"glTF", 2
JSON_CHUNK, BIN_CHUNK = b"JSON", b"BIN\x00"
ANIMATION_NAME = "Animation"  # what Blender's exporter names the one action it writes
GENERATOR = "motionlib glTF writer"


def write_glb(take: Take, out, *, metres: float) -> None:
    """Write every frame of ``take`` (a clip: :meth:`Take.slice`) to the ``.glb`` file ``out``.

    Parameters
    ----------
    take : Take
        A take of joint rotations (not points).
    out : str or PathLike
    metres : float
        Metres per unit of the take's lengths.
    """
    os.makedirs(os.path.dirname(os.path.abspath(os.fspath(out))) or ".", exist_ok=True)
    with open(out, "wb") as handle:
        handle.write(glb_bytes(take, metres=metres))


def glb_bytes(take: Take, *, metres: float) -> bytes:
    """The ``.glb`` file of :func:`write_glb` as bytes."""
    rotations, translations = local_transforms(take)
    quats = joint_quaternions(rotations)
    buffer = _Buffer()
    gltf = _skeleton(take, metres, buffer)
    gltf["animations"] = [_animation(take, quats, translations * metres, buffer)]
    gltf["accessors"], gltf["bufferViews"] = buffer.accessors, buffer.views
    gltf["buffers"] = [{"byteLength": buffer.length}]
    return pack_glb(gltf, buffer.data())


def joint_quaternions(rotations: np.ndarray) -> np.ndarray:
    """(n_frames, n_joints, 3, 3) rotations -> (n_frames, n_joints, 4) unit quaternions in
    glTF's order (x, y, z, w), each joint's sign kept continuous over time so that LINEAR
    interpolation between frames takes the short way."""
    n, J = rotations.shape[:2]
    wxyz = matrix_to_quaternion(rotations.reshape(-1, 3, 3)).reshape(n, J, 4)
    flips = np.cumsum(np.sum(wxyz[1:] * wxyz[:-1], axis=-1) < 0, axis=0) % 2
    wxyz[1:][flips.astype(bool)] *= -1
    return wxyz[..., [1, 2, 3, 0]]


def _skeleton(take, metres, buffer):
    """Asset, scene, the joint nodes under the armature node, and the skin that binds them."""
    sk = take.skeleton
    nodes = [{"name": name, "translation": _floats(offset * metres)}
             for name, offset in zip(sk.names, sk.offsets, strict=True)]
    for j, parent in enumerate(sk.parents):
        if parent >= 0:
            nodes[parent].setdefault("children", []).append(j)
    roots = [j for j, parent in enumerate(sk.parents) if parent < 0]
    nodes.append({"name": take.name or "Armature", "children": roots})
    # No "skeleton": the joints' common root is the armature node (a take may have several
    # root joints), which Blender's exporter leaves out too.
    skin = {"name": take.name or "Armature", "joints": list(range(sk.n_joints)),
            "inverseBindMatrices": buffer.add(_inverse_binds(sk, metres), "MAT4")}
    return {"asset": {"version": "2.0", "generator": GENERATOR}, "scene": 0,
            "scenes": [{"name": "Scene", "nodes": [len(nodes) - 1]}], "nodes": nodes,
            "skins": [skin]}


def _inverse_binds(sk, metres):
    """(n_joints, 16) column-major inverse rest world matrices: with the world's orientation
    at rest, a translation by minus the joint's rest position."""
    rest = np.zeros((sk.n_joints, 3))
    for j, parent in enumerate(sk.parents):
        rest[j] = sk.offsets[j] * metres + (rest[parent] if parent >= 0 else 0.0)
    matrices = np.tile(np.eye(4), (sk.n_joints, 1, 1))
    matrices[:, :3, 3] = -rest
    return matrices.transpose(0, 2, 1).reshape(sk.n_joints, 16)


def _animation(take, quats, translations, buffer):
    """One sampler and channel per animated property, all on the same key times."""
    times = np.arange(take.n_frames, dtype=np.float64) / take.fps
    time = buffer.add(times[:, None], "SCALAR", bounds=True)
    samplers, channels = [], []

    def key(node, path, values, kind):
        samplers.append({"input": time, "interpolation": "LINEAR",
                         "output": buffer.add(values, kind)})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})

    for j, names in enumerate(take.skeleton.channels):
        if any(c.endswith("position") for c in names):
            key(j, "translation", translations[:, j], "VEC3")
        key(j, "rotation", quats[:, j], "VEC4")
    return {"name": ANIMATION_NAME, "samplers": samplers, "channels": channels}


class _Buffer:
    """The binary chunk as it grows: float32 arrays, each in its own 4-byte aligned view with
    its accessor."""

    def __init__(self):
        self.parts, self.views, self.accessors, self.length = [], [], [], 0

    def add(self, values, kind, *, bounds=False):
        """Append ``values`` (count, components) as float32; the index of its accessor."""
        data = np.ascontiguousarray(values, dtype="<f4")
        raw = data.tobytes()
        self.views.append({"buffer": 0, "byteOffset": self.length, "byteLength": len(raw)})
        accessor = {"bufferView": len(self.views) - 1, "componentType": FLOAT,
                    "count": int(data.shape[0]), "type": kind}
        if bounds:  # required on animation inputs; from the float32 values as stored
            accessor["min"] = _floats(data.min(axis=0))
            accessor["max"] = _floats(data.max(axis=0))
        self.accessors.append(accessor)
        self.parts.append(raw)
        self.length += len(raw)  # float32: every view stays 4-byte aligned
        return len(self.accessors) - 1

    def data(self):
        return b"".join(self.parts)


def pack_glb(gltf: dict, binary: bytes) -> bytes:
    """A glTF binary file: the 12-byte header, the JSON chunk padded with spaces and the BIN
    chunk padded with zeros, each to 4 bytes (glTF 2.0, "Binary glTF Layout")."""
    text = json.dumps(gltf, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary += b"\x00" * (-len(binary) % 4)
    length = 12 + 8 + len(text) + 8 + len(binary)
    return b"".join([struct.pack("<4sII", GLB_MAGIC, GLB_VERSION, length),
                     struct.pack("<I4s", len(text), JSON_CHUNK), text,
                     struct.pack("<I4s", len(binary), BIN_CHUNK), binary])


def _floats(values):
    return [float(v) for v in np.asarray(values, dtype=np.float32)]
