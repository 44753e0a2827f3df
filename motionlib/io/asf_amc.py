"""CMU ASF (skeleton) and AMC (motion) reading.

The ASF bones become a BVH-like joint tree exactly as in cgspeed's BVH conversion: each bone is
a joint located at the bone's start, its offset is the parent bone's ``direction * length``
(zero for bones attached to the root, and, as cgspeed does, zero for the children of a bone
that branches: thorax -> neck and clavicles, wrist -> hand and thumb), and its local rotation is ``C @ M @ C.T`` where ``C`` is
the bone's ``axis`` frame and ``M`` the AMC rotation. Rotations compose in the ASF axis order
(``axis ... XYZ``: ``M = Rz @ Ry @ Rx``, as in the Acclaim format and cgspeed's files).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from motionlib.errors import CaptureError
from motionlib.io import _parse
from motionlib.io.numbers import finite_value
from motionlib.kinematics import euler_to_matrix
from motionlib.skeleton import Skeleton
from motionlib.take import Take

_DOF = {"tx": "Xposition", "ty": "Yposition", "tz": "Zposition",
        "rx": "Xrotation", "ry": "Yrotation", "rz": "Zrotation"}


@dataclass
class _Bone:
    name: str
    line: int
    direction: np.ndarray = field(default_factory=lambda: np.zeros(3))
    length: float = 0.0
    axis: tuple[float, float, float] = (0.0, 0.0, 0.0)
    order: str = "XYZ"
    dof: tuple[str, ...] = ()


class _AsfLines:
    def __init__(self, path):
        self.path = path
        text = Path(path).read_text(encoding="utf-8", errors="replace")
        if not text.strip():
            raise CaptureError("empty file", path=path, line=1)
        self.lines = [(n, line.split()) for n, line in enumerate(text.splitlines(), 1)
                      if line.strip() and not line.lstrip().startswith("#")]

    def error(self, message, line):
        return CaptureError(message, path=self.path, line=line)

    def numbers(self, tokens, count, what, line):
        if len(tokens) < count:
            raise self.error(f"{what} needs {count} numbers, found {len(tokens)}", line)
        try:
            values = [float(t) for t in tokens[:count]]
        except ValueError:
            raise self.error(f"{what} must be numbers, found {' '.join(tokens[:count])!r}",
                             line) from None
        if not all(math.isfinite(v) for v in values):
            raise self.error(f"{what} must be finite, found {' '.join(tokens[:count])!r}", line)
        return values


def _sections(asf: _AsfLines) -> dict[str, list[tuple[int, list[str]]]]:
    sections: dict[str, list] = {}
    current = None
    for n, tokens in asf.lines:
        if tokens[0].startswith(":"):
            current = tokens[0][1:].lower()
            sections[current] = [(n, tokens[1:])] if len(tokens) > 1 else []
        elif current is not None:
            sections[current].append((n, tokens))
    for required in ("root", "bonedata", "hierarchy"):
        if required not in sections:
            raise asf.error(f"missing :{required} section", asf.lines[-1][0])
    return sections


def _angle_scale(asf: _AsfLines, units) -> float:
    for n, tokens in units:
        if tokens[0].lower() == "angle" and len(tokens) > 1:
            unit = tokens[1].lower()
            if unit not in ("deg", "rad"):
                raise asf.error(f"angle unit must be deg or rad, found {tokens[1]!r}", n)
            return 1.0 if unit == "deg" else 180.0 / math.pi
    return 1.0  # the Acclaim default is degrees


def _parse_bones(asf: _AsfLines, lines, to_deg: float) -> dict[str, _Bone]:
    bones: dict[str, _Bone] = {}
    bone = None
    for n, tokens in lines:
        key = tokens[0].lower()
        if key == "begin":
            bone = _Bone(name="", line=n)
        elif bone is None:
            raise asf.error(f"{tokens[0]!r} outside a begin ... end bone block", n)
        elif key == "end":
            if not bone.name:
                raise asf.error("bone without a name", bone.line)
            bones[bone.name] = bone
            bone = None
        else:
            _bone_field(asf, bone, key, tokens, n, to_deg)
    return bones


def _bone_field(asf, bone: _Bone, key: str, tokens, n: int, to_deg: float) -> None:
    if key == "name" and len(tokens) > 1:
        bone.name = tokens[1]
    elif key == "direction":
        bone.direction = np.array(asf.numbers(tokens[1:], 3, f"direction of {bone.name}", n))
    elif key == "length":
        bone.length = asf.numbers(tokens[1:], 1, f"length of {bone.name}", n)[0]
    elif key == "axis":
        angles = asf.numbers(tokens[1:], 3, f"axis of {bone.name}", n)
        bone.axis = tuple(a * to_deg for a in angles)
        bone.order = _axis_order(asf, tokens[4] if len(tokens) > 4 else "XYZ", n)
    elif key == "dof":
        for d in tokens[1:]:
            if d.lower() not in _DOF or d.lower().startswith("t"):
                raise asf.error(f"unsupported dof {d!r} of bone {bone.name} "
                                "(expected rx, ry, rz)", n)
        bone.dof = tuple(_DOF[d.lower()] for d in tokens[1:])


def _axis_order(asf, token: str, n: int) -> str:
    order = token.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise asf.error(f"axis order must be a permutation of XYZ, found {token!r}", n)
    return order


def _parse_root(asf: _AsfLines, lines, to_deg: float) -> _Bone:
    root = _Bone(name="root", line=lines[0][0] if lines else 1)
    for n, tokens in lines:
        key = tokens[0].lower()
        if key == "order":
            if any(t.lower() not in _DOF for t in tokens[1:]):
                raise asf.error(f"root order must use TX TY TZ RX RY RZ, found "
                                f"{' '.join(tokens[1:])!r}", n)
            root.dof = tuple(_DOF[t.lower()] for t in tokens[1:])
        elif key == "axis" and len(tokens) > 1:
            root.order = _axis_order(asf, tokens[1], n)
        elif key == "orientation":
            root.axis = tuple(a * to_deg for a in asf.numbers(tokens[1:], 3, "root orientation", n))
        elif key == "position":
            root.direction = np.array(asf.numbers(tokens[1:], 3, "root position", n))
    return root


def _parse_hierarchy(asf: _AsfLines, lines, bones: dict[str, _Bone]) -> dict[str, list[str]]:
    children: dict[str, list[str]] = {}
    for n, tokens in lines:
        if tokens[0].lower() in ("begin", "end"):
            continue
        for name in tokens:
            if name != "root" and name not in bones:
                raise asf.error(f"bone {name!r} in :hierarchy is not defined in :bonedata", n)
        children.setdefault(tokens[0], []).extend(tokens[1:])
    return children


def _axis_matrix(bone: _Bone) -> np.ndarray:
    # ASF "axis a b c XYZ" applies X first: C = Rz(c) @ Ry(b) @ Rx(a).
    angles = dict(zip("XYZ", bone.axis, strict=True))
    order = bone.order[::-1]
    return euler_to_matrix(np.array([[angles[a] for a in order]]), order)[0]


@dataclass
class Asf:
    """A parsed ASF: the joint tree and the factor from its angle unit to degrees."""

    skeleton: Skeleton
    to_deg: float
    path: str


def read_asf(path: str | os.PathLike) -> Asf:
    """Read a CMU ASF skeleton.

    Returns
    -------
    Asf
        ``skeleton`` has one joint per bone (``root`` first, depth-first in :hierarchy order),
        ``axes`` holding each bone's ``C`` and channels in each bone's ``dof`` order.
    """
    path = os.fspath(path)
    asf = _AsfLines(path)
    sections = _sections(asf)
    to_deg = _angle_scale(asf, sections.get("units", []))
    bones = _parse_bones(asf, sections["bonedata"], to_deg)
    root = _parse_root(asf, sections["root"], to_deg)
    children = _parse_hierarchy(asf, sections["hierarchy"], bones)
    order: list[tuple[str, int]] = []  # (bone name, parent joint index)

    def visit(name: str, parent: int) -> None:
        if any(name == seen for seen, _ in order):
            raise asf.error(f"bone {name!r} appears twice in :hierarchy", bones[name].line)
        order.append((name, parent))
        me = len(order) - 1
        for child in children.get(name, []):
            visit(child, me)

    visit("root", -1)
    return Asf(skeleton=_skeleton(order, bones, root), to_deg=to_deg, path=path)


def _skeleton(order, bones: dict[str, _Bone], root: _Bone) -> Skeleton:
    by_name = {**bones, "root": root}
    names = [name for name, _ in order]
    parents = [p for _, p in order]
    n_children = np.bincount([p for p in parents if p >= 0], minlength=len(names))
    # cgspeed drops the length of a bone that branches (thorax, wrists): its children start
    # where it starts. Matching that keeps AMC and cgspeed BVH positions identical.
    offsets = [root.direction] + [
        np.zeros(3) if p == 0 or n_children[p] > 1
        else bones[names[p]].direction * bones[names[p]].length
        for _, p in order[1:]]
    has_child = set(parents)
    end_sites = {j: bones[n].direction * bones[n].length
                 for j, n in enumerate(names) if j and j not in has_child}
    return Skeleton(
        names=names, parents=parents, offsets=offsets,
        channels=[by_name[n].dof for n in names],
        rotation_orders=[by_name[n].order[::-1] for n in names],
        axes=np.stack([_axis_matrix(by_name[n]) for n in names]),
        end_sites=end_sites)


def read_amc(path: str | os.PathLike, asf: str | os.PathLike | Asf) -> Take:
    """Read a CMU AMC motion with its ASF skeleton.

    Parameters
    ----------
    path : str or PathLike
        The ``.amc`` file; frame numbers must run 1, 2, … N.
    asf : str, PathLike or Asf
        Its skeleton.

    Returns
    -------
    Take
        ``format == "amc"``, 120 fps (the CMU capture rate; AMC stores no rate), rotations in
        degrees, frame 0 = AMC frame 1, ``rest_pose_frame`` None.
    """
    path = os.fspath(path)
    if not isinstance(asf, Asf):
        asf = read_asf(asf)
    data = Path(path).read_bytes()
    offset, first_line = _amc_body(data, path)
    sk = asf.skeleton
    channels = _amc_fast(data, offset, sk)
    if channels is None:
        body = data[offset:].decode("utf-8", "replace")
        channels = _amc_lines(body, first_line, asf, path)
    if asf.to_deg != 1.0:
        rot = [sk.channel_starts[j] + k for j, names in enumerate(sk.channels)
               for k, name in enumerate(names) if name.endswith("rotation")]
        channels[:, rot] *= asf.to_deg
    return Take(name=Path(path).stem, format="amc", fps=AMC_FPS, frame_time=1.0 / AMC_FPS,
                channels=channels, skeleton=sk, rest_pose_frame=None, path=path)


AMC_FPS = 120.0


def _amc_body(data: bytes, path) -> tuple[int, int]:
    """Skip the ``#``/``:`` header: byte offset and line number of the first frame line."""
    if not data.strip():
        raise CaptureError("empty file", path=path, line=1)
    pos, line = 0, 1
    while pos < len(data):
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end + 1
        stripped = data[pos:end].strip()
        if stripped and not stripped.startswith((b"#", b":")):
            return pos, line
        pos, line = end, line + 1
    raise CaptureError("no frames after the header", path=path, line=line - 1)


def _first_frame_layout(data: bytes, offset: int, sk: Skeleton) -> list[str] | None:
    """Bones of the first frame in their order, or None."""
    dof = {name: len(ch) for name, ch in zip(sk.names, sk.channels, strict=True)}
    size = 4096
    while True:
        tokens = data[offset:offset + size].decode("utf-8", "replace").split()
        complete = offset + size >= len(data)
        if not complete:
            tokens = tokens[:-1]  # the last one may be cut in half
        names, i = [], 1
        while i < len(tokens) and tokens[i] in dof:
            names.append(tokens[i])
            i += 1 + dof[tokens[i]]
        if i < len(tokens) or complete:
            break
        size *= 4
    if not names or len(set(names)) < len(names) or (i < len(tokens) and
                                                     not tokens[i].isdigit()):
        return None
    return names


def _amc_fast(data: bytes, offset: int, sk: Skeleton) -> np.ndarray | None:
    """One pass of the compiled reader when every frame lists the same bones in the same order
    as the first one (as CMU writes them), else None."""
    layout = _first_frame_layout(data, offset, sk)
    if layout is None:
        return None
    joints = [sk.names.index(name) for name in layout]
    counts = np.array([len(sk.channels[j]) for j in joints], np.intp)
    if not counts.sum():
        return None
    # A frame takes one line per bone plus its number: an upper bound on the frames.
    capacity = data.count(b"\n", offset) // (len(layout) + 1) + 1
    values = np.empty((capacity, int(counts.sum())))
    n = _parse.read_frames(data, offset, [name.encode() for name in layout], counts, values)
    if n < 0:
        return None
    channels = np.zeros((n, sk.n_channels))
    first = 0
    for j, count in zip(joints, counts, strict=True):
        start = sk.channel_starts[j]
        channels[:, start:start + count] = values[:n, first:first + count]
        first += count
    return channels


def _amc_lines(body: str, first_line: int, asf: Asf, path) -> np.ndarray:
    """Line-by-line parse that names the first thing wrong (also the general fallback)."""
    sk = asf.skeleton
    index = {name: j for j, name in enumerate(sk.names)}
    starts = sk.channel_starts
    frames: list[np.ndarray] = []
    seen: set[str] = set()
    for n, line in enumerate(body.splitlines(), first_line):
        tokens = line.split()
        if not tokens or tokens[0].startswith("#"):
            continue
        if tokens[0].lstrip("-").isdigit() and len(tokens) == 1:
            expected = len(frames) + 1
            if int(tokens[0]) != expected:
                raise CaptureError(f"frame number {tokens[0]} out of sequence, expected "
                                   f"{expected}", path=path, line=n)
            frames.append(np.zeros(sk.n_channels))
            seen = set()
            continue
        name = tokens[0]
        if not frames:
            raise CaptureError(f"{name[:40]!r} before the first frame number", path=path,
                               line=n)
        if name not in index:
            raise CaptureError(f"bone {name[:40]!r} is not in the skeleton "
                               f"{os.path.basename(asf.path)}", path=path, line=n)
        if name in seen:
            raise CaptureError(f"bone {name!r} listed twice in frame {len(frames)}",
                               path=path, line=n)
        seen.add(name)
        j = index[name]
        count = len(sk.channels[j])
        if len(tokens) - 1 != count:
            raise CaptureError(f"bone {name!r} needs {count} values, found {len(tokens) - 1}",
                               path=path, line=n)
        bone = f" of bone {name!r}"
        frames[-1][starts[j]:starts[j] + count] = [
            finite_value(tok, "value ", bone, path, n) for tok in tokens[1:]]
    return np.array(frames).reshape(len(frames), sk.n_channels)
