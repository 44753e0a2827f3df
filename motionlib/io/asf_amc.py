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

from motionlib.errors import CaptureError, shorten
from motionlib.io import _parse
from motionlib.io.numbers import finite_value
from motionlib.io.text import read_lines_bytes
from motionlib.kinematics import euler_to_matrix
from motionlib.skeleton import Skeleton
from motionlib.take import DEFAULT_LIMITS, Limits, Take, check_size, max_frames_for

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
    def __init__(self, path, limits: Limits):
        self.path = path
        self.limits = limits
        text = read_lines_bytes(path).decode("utf-8", "replace")
        if not text.strip():
            raise CaptureError("empty file", path=path, line=1)
        lines = text.split("\n")
        self.lines = [(n, line.split()) for n, line in enumerate(lines, 1)
                      if line.strip() and not line.lstrip().startswith("#")]
        if not self.lines:
            raise CaptureError("no ASF sections (:root, :bonedata, :hierarchy), only comments",
                               path=path, line=len(lines))

    def error(self, message, line):
        return CaptureError(message, path=self.path, line=line)

    def numbers(self, tokens, count, what, line):
        if len(tokens) < count:
            raise self.error(f"{what} needs {count} numbers, found {len(tokens)}", line)
        try:
            values = [float(t) for t in tokens[:count]]
        except ValueError:
            raise self.error(f"{what} must be numbers, found {shorten(' '.join(tokens[:count]))}",
                             line) from None
        if not all(math.isfinite(v) for v in values):
            raise self.error(f"{what} must be finite, found {shorten(' '.join(tokens[:count]))}", line)
        bound = self.limits.max_length
        if any(abs(v) > bound for v in values):
            raise self.error(f"{what} is {shorten(' '.join(tokens[:count]))}, beyond the limit of "
                             f"±{bound:g}", line)
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
                raise asf.error(f"angle unit must be deg or rad, found {shorten(tokens[1])}", n)
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
            raise asf.error(f"{shorten(tokens[0])} outside a begin ... end bone block", n)
        elif key == "end":
            _add_bone(asf, bones, bone)
            bone = None
        else:
            _bone_field(asf, bone, key, tokens, n, to_deg)
    return bones


def _add_bone(asf: _AsfLines, bones: dict[str, _Bone], bone: _Bone) -> None:
    limits = asf.limits
    if not bone.name:
        raise asf.error("bone without a name", bone.line)
    if len(bone.name) > limits.max_name_length:
        raise asf.error(f"bone name {shorten(bone.name)} is longer than the limit of "
                        f"{limits.max_name_length} characters", bone.line)
    if bone.name in bones or bone.name == "root":
        raise asf.error(f"bone {bone.name!r} is defined twice (or is named like the root)",
                        bone.line)
    if np.abs(bone.direction * bone.length).max() > limits.max_length:
        raise asf.error(f"bone {bone.name} is {np.linalg.norm(bone.direction) * bone.length:g} "
                        f"long (direction x length), beyond the limit of {limits.max_length:g}",
                        bone.line)
    if len(bones) + 1 >= limits.max_joints:  # the root is a joint too
        raise asf.error(f"more than {limits.max_joints} joints (the limit); bone "
                        f"{bone.name} is one too many", bone.line)
    bones[bone.name] = bone


def _bone_field(asf, bone: _Bone, key: str, tokens, n: int, to_deg: float) -> None:
    if key == "name" and len(tokens) > 1:
        bone.name = tokens[1]
        if len(bone.name) > asf.limits.max_name_length:
            raise asf.error(f"bone name {shorten(bone.name)} is longer than the limit of "
                            f"{asf.limits.max_name_length} characters", n)
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
                raise asf.error(f"unsupported dof {shorten(d)} of bone {bone.name} "
                                "(expected rx, ry, rz)", n)
        bone.dof = tuple(_DOF[d.lower()] for d in tokens[1:])


def _axis_order(asf, token: str, n: int) -> str:
    order = token.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise asf.error(f"axis order must be a permutation of XYZ, found {shorten(token)}", n)
    return order


def _parse_root(asf: _AsfLines, lines, to_deg: float) -> _Bone:
    root = _Bone(name="root", line=lines[0][0] if lines else 1)
    for n, tokens in lines:
        key = tokens[0].lower()
        if key == "order":
            if any(t.lower() not in _DOF for t in tokens[1:]):
                raise asf.error(f"root order must use TX TY TZ RX RY RZ, found "
                                f"{shorten(' '.join(tokens[1:]))}", n)
            root.dof = tuple(_DOF[t.lower()] for t in tokens[1:])
        elif key == "axis" and len(tokens) > 1:
            root.order = _axis_order(asf, tokens[1], n)
        elif key == "orientation":
            root.axis = tuple(a * to_deg for a in asf.numbers(tokens[1:], 3, "root orientation", n))
        elif key == "position":
            root.direction = np.array(asf.numbers(tokens[1:], 3, "root position", n))
    return root


def _parse_hierarchy(asf: _AsfLines, lines,
                     bones: dict[str, _Bone]) -> dict[str, list[tuple[str, int]]]:
    """Each parent's children, each with the :hierarchy line that names it."""
    children: dict[str, list[tuple[str, int]]] = {}
    for n, tokens in lines:
        if tokens[0].lower() in ("begin", "end"):
            continue
        for name in tokens:
            if name != "root" and name not in bones:
                raise asf.error(f"bone {shorten(name)} in :hierarchy is not defined in "
                                ":bonedata", n)
        if "root" in tokens[1:]:
            raise asf.error(f"'root' is listed as a child of {tokens[0]!r}; the root has no "
                            "parent", n)
        children.setdefault(tokens[0], []).extend((child, n) for child in tokens[1:])
    return children


def _joint_order(asf: _AsfLines, children) -> list[tuple[str, int]]:
    """(bone name, parent joint index) depth-first from the root, in :hierarchy order; with a
    stack, so a chain of bones thousands deep is read like a flat list."""
    order: list[tuple[str, int]] = []
    placed: set[str] = set()
    stack = [("root", -1, 0)]
    while stack:
        name, parent, line = stack.pop()
        if name in placed:
            raise asf.error(f"bone {name!r} appears twice in :hierarchy", line)
        placed.add(name)
        order.append((name, parent))
        me = len(order) - 1
        stack += [(child, me, n) for child, n in reversed(children.get(name, []))]
    return order


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


def read_asf(path: str | os.PathLike, *, limits: Limits = DEFAULT_LIMITS) -> Asf:
    """Read a CMU ASF skeleton.

    Linear in the size of the file; bones beyond ``limits.max_joints``, names longer than
    ``limits.max_name_length`` and lengths beyond ``limits.max_length`` are refused.

    Returns
    -------
    Asf
        ``skeleton`` has one joint per bone (``root`` first, depth-first in :hierarchy order),
        ``axes`` holding each bone's ``C`` and channels in each bone's ``dof`` order.
    """
    path = os.fspath(path)
    asf = _AsfLines(path, limits)
    sections = _sections(asf)
    to_deg = _angle_scale(asf, sections.get("units", []))
    bones = _parse_bones(asf, sections["bonedata"], to_deg)
    root = _parse_root(asf, sections["root"], to_deg)
    children = _parse_hierarchy(asf, sections["hierarchy"], bones)
    order = _joint_order(asf, children)
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


def read_amc(path: str | os.PathLike, asf: str | os.PathLike | Asf, *,
             limits: Limits = DEFAULT_LIMITS) -> Take:
    """Read a CMU AMC motion with its ASF skeleton.

    Parameters
    ----------
    path : str or PathLike
        The ``.amc`` file; frame numbers must run 1, 2, … N, and every frame list the
        bones of the first (a file cut off part-way through a frame is refused).
    asf : str, PathLike or Asf
        Its skeleton.
    limits : Limits, optional
        Joints, frames and sizes to refuse; checked before the frames are allocated.

    Returns
    -------
    Take
        ``format == "amc"``, 120 fps (the CMU capture rate; AMC stores no rate), rotations in
        degrees, frame 0 = AMC frame 1, ``rest_pose_frame`` None.
    """
    path = os.fspath(path)
    if not isinstance(asf, Asf):
        asf = read_asf(asf, limits=limits)
    data = read_lines_bytes(path)
    offset, first_line = _amc_body(data, path)
    sk = asf.skeleton
    positions = [sk.channel_starts[j] + k for j, names in enumerate(sk.channels)
                 for k, name in enumerate(names) if name.endswith("position")]
    bounds = np.full(sk.n_channels, np.inf)
    bounds[positions] = limits.max_length
    channels = _amc_fast(data, offset, sk, limits)
    if channels is None or (np.abs(channels[:, positions]) > limits.max_length).any():
        body = data[offset:].decode("utf-8", "replace")
        channels = _amc_lines(body, first_line, asf, path, bounds,
                              max_frames_for(sk.n_joints, sk.n_channels, len(data), limits))
    check_size(len(channels), sk.n_joints, sk.n_channels, len(data), limits, path=path)
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


def _amc_fast(data: bytes, offset: int, sk: Skeleton,
              limits: Limits = DEFAULT_LIMITS) -> np.ndarray | None:
    """One pass of the compiled reader when every frame lists the same bones in the same order
    as the first one (as CMU writes them), else None."""
    layout = _first_frame_layout(data, offset, sk)
    if layout is None:
        return None
    index = {name: j for j, name in enumerate(sk.names)}
    joints = [index[name] for name in layout]
    counts = np.array([len(sk.channels[j]) for j in joints], np.intp)
    if not counts.sum():
        return None
    # A frame takes one line per bone plus its number: an upper bound on the frames.
    capacity = data.count(b"\n", offset) // (len(layout) + 1) + 1
    values = np.empty((capacity, int(counts.sum())))
    n = _parse.read_frames(data, offset, [name.encode() for name in layout], counts, values)
    if n < 0 or n > max_frames_for(sk.n_joints, sk.n_channels, len(data), limits):
        return None  # the careful reader names the line where the limit is passed
    channels = np.zeros((n, sk.n_channels))
    first = 0
    for j, count in zip(joints, counts, strict=True):
        start = sk.channel_starts[j]
        channels[:, start:start + count] = values[:n, first:first + count]
        first += count
    return channels


def _amc_lines(body: str, first_line: int, asf: Asf, path, bounds: np.ndarray | None = None,
               max_frames: int | None = None) -> np.ndarray:
    """Line-by-line parse that names the first thing wrong (also the general fallback).

    ``bounds`` is the largest absolute value of each channel, ``max_frames`` the most
    frames the limits admit (no bound when None).
    """
    sk = asf.skeleton
    bounds = np.full(sk.n_channels, np.inf) if bounds is None else bounds
    max_frames = math.inf if max_frames is None else max_frames
    index = {name: j for j, name in enumerate(sk.names)}
    starts = sk.channel_starts
    frames: list[np.ndarray] = []
    seen: set[str] = set()
    bones: set[str] = set()  # those of frame 1
    frame_line = first_line
    for n, line in enumerate(body.split("\n"), first_line):
        tokens = line.split()
        if not tokens or tokens[0].startswith("#"):
            continue
        if tokens[0].lstrip("-").isdigit() and len(tokens) == 1:
            _check_frame_start(frames, seen, tokens[0], n, frame_line, path, max_frames, sk)
            if len(frames) == 1:
                bones = seen
            elif len(frames) > 1:
                _check_same_bones(bones, seen, len(frames), frame_line, path)
            frames.append(np.zeros(sk.n_channels))
            seen, frame_line = set(), n
            continue
        name = tokens[0]
        if not frames:
            raise CaptureError(f"{shorten(name)} before the first frame number", path=path,
                               line=n)
        if name not in index:
            raise CaptureError(f"bone {shorten(name)} is not in the skeleton "
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
        values = [finite_value(tok, "value ", bone, path, n) for tok in tokens[1:]]
        beyond = np.flatnonzero(np.abs(values) > bounds[starts[j]:starts[j] + count])
        if beyond.size:
            raise CaptureError(f"value {shorten(tokens[1 + beyond[0]])}{bone} is a position "
                               f"beyond the limit of ±{bounds[starts[j] + beyond[0]]:g}",
                               path=path, line=n)
        frames[-1][starts[j]:starts[j] + count] = values
    if frames and not seen:
        raise CaptureError(f"frame {len(frames)} lists no bones", path=path, line=frame_line)
    if len(frames) > 1:
        _check_same_bones(bones, seen, len(frames), frame_line, path)
    return np.array(frames).reshape(len(frames), sk.n_channels)


def _check_same_bones(bones: set[str], seen: set[str], frame: int, line: int, path) -> None:
    """Every frame lists the bones of the first one: a frame with fewer is cut off (a file
    that ends part-way through a frame), and its other bones would read as zero angles."""
    if seen == bones:
        return
    missing, extra = sorted(bones - seen), sorted(seen - bones)
    if missing:
        more = f" and {len(missing) - 1} more" if len(missing) > 1 else ""
        what = f"lacks bone {missing[0]!r}{more} that frame 1 lists: a cut-off or damaged file"
    else:
        what = f"lists bone {extra[0]!r}, which frame 1 does not: a damaged file"
    raise CaptureError(f"frame {frame} {what}", path=path, line=line)


def _check_frame_start(frames, seen, token: str, n: int, frame_line: int, path,
                       max_frames: int, sk: Skeleton) -> None:
    """A frame number may start a frame: it is the next one, the frame before it listed a
    bone, and the limits admit one more frame."""
    expected = len(frames) + 1
    if len(token) > 18 or int(token) != expected:
        raise CaptureError(f"frame number {token[:20]} out of sequence, expected "
                           f"{expected}", path=path, line=n)
    if frames and not seen:
        raise CaptureError(f"frame {len(frames)} lists no bones", path=path, line=frame_line)
    if expected > max_frames:
        raise CaptureError(f"frame {expected} is one more than the limits admit for "
                           f"{sk.n_joints} joints and {sk.n_channels} channels "
                           f"({max_frames} frames)", path=path, line=n)
