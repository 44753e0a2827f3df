"""BVH reading and writing.

The HIERARCHY is parsed token by token (it is small); the MOTION block, which is nearly all of
the file, is read in one call to the compiled number reader (:mod:`motionlib.io.numbers`),
which also checks its shape (values per line, number of lines). Only when that declines does a
line-by-line pass run, to read what the fast reader declines (``nan`` and friends are then
rejected) and to find and name the bad line.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from motionlib.errors import CaptureError, shorten
from motionlib.io.numbers import finite_value, read_rows
from motionlib.io.text import lone_cr_to_lf, read_lines_bytes
from motionlib.skeleton import CHANNEL_NAMES, ROTATION_CHANNELS, Skeleton
from motionlib.take import DEFAULT_LIMITS, Limits, Take, check_size, frame_range

_CHANNEL_BY_LOWER = {c.lower(): c for c in CHANNEL_NAMES}
_MOTION = re.compile(rb"^[ \t]*MOTION\b", re.MULTILINE | re.IGNORECASE)
_NOT_BLANK = re.compile(rb"[^ \t\n\r\x0b\x0c]")  # what bytes.strip() keeps


_TOKEN = re.compile(r"\n|[{}]|[^\s{}]+")


def _short(token: str) -> str:
    """A token for an error message: quoted, and cut if it is binary junk or very long."""
    return shorten(token)


def _scan(text: str):
    """(token, line number) pairs, braces split off, produced as they are asked for."""
    line = 1
    for m in _TOKEN.finditer(text):
        token = m.group()
        if token == "\n":
            line += 1
        else:
            yield token, line


class _Tokens:
    """The HIERARCHY as a stream of (token, line number) with one token of lookahead.

    Tokens are made one at a time, so a limit reached early stops the reading early.
    """

    def __init__(self, text: str, path):
        self._items = _scan(text)
        self._ahead = next(self._items, None)
        self.path = path
        self.last_line = max(1, text.count("\n") + 1)

    def error(self, message: str, line: int | None = None) -> CaptureError:
        if line is None:
            line = self._ahead[1] if self._ahead is not None else self.last_line
        return CaptureError(message, path=self.path, line=line)

    def peek(self) -> str | None:
        return self._ahead[0] if self._ahead is not None else None

    def next(self, what: str) -> tuple[str, int]:
        if self._ahead is None:
            raise self.error(f"unexpected end of HIERARCHY, expected {what}")
        item, self._ahead = self._ahead, next(self._items, None)
        return item

    def expect(self, keyword: str) -> None:
        tok, line = self.next(repr(keyword))
        if tok.upper() != keyword.upper():
            raise self.error(f"expected {keyword!r}, found {_short(tok)}", line)

    def number(self, what: str, bound: float) -> float:
        tok, line = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise self.error(f"{what} must be a number, found {_short(tok)}", line) from None
        if not math.isfinite(value):
            raise self.error(f"{what} must be finite, found {_short(tok)}", line)
        if abs(value) > bound:
            raise self.error(f"{what} is {_short(tok)}, beyond the limit of ±{bound:g}", line)
        return value


class _Builder:
    def __init__(self, limits: Limits):
        self.names, self.parents, self.offsets, self.channels = [], [], [], []
        self.seen: set[str] = set()
        self.end_sites: dict[int, np.ndarray] = {}
        self.limits = limits


def _parse_joints(tokens: _Tokens, b: _Builder) -> None:
    """The root joint and everything nested in it, with a stack instead of recursion (a
    hierarchy nested thousands deep is read like a flat one)."""
    open_joints = [_open_joint(tokens, b, -1)]
    while open_joints:
        j = open_joints[-1]
        tok, line = tokens.next(f"JOINT, End Site or '}}' closing {b.names[j]}")
        if tok == "}":
            open_joints.pop()
        elif tok.upper() == "JOINT":
            open_joints.append(_open_joint(tokens, b, j))
        elif tok.upper() == "END":
            _parse_end_site(tokens, b, j)
        else:
            raise tokens.error(f"unexpected {_short(tok)} in joint {b.names[j]}", line)


def _open_joint(tokens: _Tokens, b: _Builder, parent: int) -> int:
    """Read a joint's name, OFFSET and CHANNELS; return its index."""
    name, line = tokens.next("a joint name")
    limits = b.limits
    if name in ("{", "}"):
        raise tokens.error(f"missing joint name before {name!r}", line)
    if len(name) > limits.max_name_length:
        raise tokens.error(f"joint name {_short(name)} is longer than the limit of "
                           f"{limits.max_name_length} characters", line)
    if name in b.seen:
        raise tokens.error(f"duplicate joint name {name!r}", line)
    if len(b.names) == limits.max_joints:
        raise tokens.error(f"more than {limits.max_joints} joints (the limit); joint {name} "
                           "is one too many", line)
    j = len(b.names)
    b.seen.add(name)
    b.names.append(name)
    b.parents.append(parent)
    tokens.expect("{")
    tokens.expect("OFFSET")
    b.offsets.append([tokens.number(f"OFFSET of {name}", limits.max_length) for _ in range(3)])
    b.channels.append(_parse_channels(tokens, name) if tokens.peek() == "CHANNELS" else ())
    return j


def _parse_channels(tokens: _Tokens, name: str) -> tuple[str, ...]:
    tokens.next("CHANNELS")
    tok, line = tokens.next("a channel count")
    if tok not in ("0", "1", "2", "3", "4", "5", "6"):
        raise tokens.error(f"channel count of {name} must be 0 to 6, found {_short(tok)}", line)
    channels = []
    for _ in range(int(tok)):
        tok, line = tokens.next(f"a channel name of {name}")
        if tok.lower() not in _CHANNEL_BY_LOWER:
            raise tokens.error(f"unknown channel {_short(tok)} for joint {name} (expected one of "
                               f"{', '.join(CHANNEL_NAMES)})", line)
        channels.append(_CHANNEL_BY_LOWER[tok.lower()])
    if len(set(channels)) != len(channels):
        raise tokens.error(f"repeated channel in {' '.join(channels)} of joint {name}", line)
    return tuple(channels)


def _parse_end_site(tokens: _Tokens, b: _Builder, j: int) -> None:
    tokens.expect("Site")
    tokens.expect("{")
    tokens.expect("OFFSET")
    b.end_sites[j] = np.array([tokens.number(f"End Site OFFSET of {b.names[j]}",
                                             b.limits.max_length) for _ in range(3)])
    tokens.expect("}")


def parse_hierarchy(text: str, path=None, *, limits: Limits = DEFAULT_LIMITS) -> Skeleton:
    """Skeleton from the HIERARCHY section of a BVH file (everything before ``MOTION``).

    Linear in the size of the text; joints beyond ``limits.max_joints``, names longer than
    ``limits.max_name_length`` and offsets beyond ``limits.max_length`` are refused.
    """
    tokens = _Tokens(text, path)
    if tokens.peek() is None:
        raise tokens.error("empty HIERARCHY")
    tokens.expect("HIERARCHY")
    tokens.expect("ROOT")
    b = _Builder(limits)
    _parse_joints(tokens, b)
    if tokens.peek() is not None:
        tok, line = tokens.next("")
        what = "a second ROOT (only one skeleton per file is supported)" if tok.upper() == "ROOT" \
            else _short(tok)
        raise tokens.error(f"unexpected {what} after the root joint closed", line)
    orders = ["".join(c[0] for c in chans if c in ROTATION_CHANNELS) for chans in b.channels]
    return Skeleton(names=b.names, parents=b.parents, offsets=b.offsets, channels=b.channels,
                    rotation_orders=orders, end_sites=b.end_sites)


def _next_line(data: bytes, pos: int, line: int) -> tuple[str, int, int]:
    """The next non-blank line at or after byte ``pos``: (text, line number, byte after it)."""
    while pos < len(data):
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end + 1
        text = data[pos:end].decode("utf-8", "replace").strip()
        if text:
            return text, line, end
        pos, line = end, line + 1
    return "", line, pos


def _motion_header(data: bytes, pos: int, line: int, path,
                   limits: Limits) -> tuple[int, float, int, int, int]:
    """Parse ``Frames:`` and ``Frame Time:``.

    Returns (n_frames, frame_time, body byte, body line, line of ``Frames:``).
    """
    text, line, pos = _next_line(data, pos, line)
    m = re.fullmatch(r"Frames:\s*(\S+)", text, re.IGNORECASE)
    if not m:
        raise CaptureError(f"expected 'Frames: <count>' after MOTION, found {text[:40]!r}",
                           path=path, line=line)
    if not re.fullmatch(r"[0-9]+", m.group(1)):
        raise CaptureError(f"frame count must be a whole number, found {_short(m.group(1))}",
                           path=path, line=line)
    if len(m.group(1)) > 18:  # int() of a megabyte of digits is slow (and far past any limit)
        raise CaptureError(f"frame count {_short(m.group(1))} is more than the limit of "
                           f"{limits.max_frames}", path=path, line=line)
    n_frames, frames_line = int(m.group(1)), line
    text, line, pos = _next_line(data, pos, line + 1)
    m = re.fullmatch(r"Frame\s+Time:\s*(\S+)", text, re.IGNORECASE)
    if not m:
        raise CaptureError(f"expected 'Frame Time: <seconds>', found {text[:40]!r}",
                           path=path, line=line)
    try:
        frame_time = float(m.group(1))
    except ValueError:
        frame_time = math.nan
    if not (math.isfinite(frame_time) and frame_time > 0):
        raise CaptureError(f"frame time must be a positive number of seconds, found "
                           f"{_short(m.group(1))}", path=path, line=line)
    if not limits.min_frame_time <= frame_time <= limits.max_frame_time:
        raise CaptureError(f"frame time {_short(m.group(1))} is outside "
                           f"{limits.min_frame_time:g} to {limits.max_frame_time:g} seconds",
                           path=path, line=line)
    return n_frames, frame_time, pos, line + 1, frames_line


def _position_columns(skeleton: Skeleton) -> np.ndarray:
    """Columns of the position channels, shape (k,)."""
    starts = skeleton.channel_starts
    return np.array([starts[j] + k for j, names in enumerate(skeleton.channels)
                     for k, name in enumerate(names) if name.endswith("position")], np.intp)


def _parse_motion(data: bytes, pos: int, line: int, n_frames: int, skeleton: Skeleton,
                  path, limits: Limits) -> np.ndarray:
    """Frame values as (n_frames, n_channels); ``line`` is the line number of byte ``pos``."""
    n_channels = skeleton.n_channels
    positions = _position_columns(skeleton)
    bounds = np.full(n_channels, np.inf)
    bounds[positions] = limits.max_length
    values = read_rows(data, pos, n_frames, n_channels)
    # Only the few position columns are copied for the check (not the whole take).
    if values is not None and not (np.abs(values[:, positions]) > limits.max_length).any():
        return values
    # Slow path: nan, no channels, a position out of bounds, or something wrong that needs
    # a line number.
    return _parse_motion_lines(data[pos:].decode("utf-8", "replace"), line, n_frames,
                               n_channels, path, bounds)


def _parse_motion_lines(text: str, first_line: int, n_frames: int, n_channels: int,
                        path, bounds: np.ndarray) -> np.ndarray:
    rows = []
    last = first_line
    for i, raw in enumerate(text.splitlines()):
        tokens = raw.split()
        if not tokens:
            continue
        last = first_line + i
        if len(rows) == n_frames:
            raise CaptureError(f"more frame lines than the {n_frames} declared by 'Frames:'",
                               path=path, line=last)
        if len(tokens) != n_channels:
            raise CaptureError(f"frame {len(rows)}: expected {n_channels} values, found "
                               f"{len(tokens)}", path=path, line=last)
        row = [finite_value(tok, f"frame {len(rows)}, value {k + 1}: ", "", path, last)
               for k, tok in enumerate(tokens)]
        beyond = np.flatnonzero(np.abs(row) > bounds)
        if beyond.size:
            k = int(beyond[0])
            raise CaptureError(f"frame {len(rows)}, value {k + 1}: {_short(tokens[k])} is a "
                               f"position beyond the limit of ±{bounds[k]:g}", path=path,
                               line=last)
        rows.append(row)
    if len(rows) < n_frames:
        raise CaptureError(f"truncated MOTION section: 'Frames: {n_frames}' but the file ends "
                           f"after {len(rows)} frame lines", path=path, line=last)
    return np.array(rows, dtype=np.float64).reshape(n_frames, n_channels)


def detect_rest_pose(skeleton: Skeleton, channels: np.ndarray, *,
                     atol: float = 0.0) -> int | None:
    """Index of an added rest (T-) pose at the start of a take, or None.

    Converters such as cgspeed's prepend a frame whose rotations are whole degrees, nearly all
    zero (a few fixed limb corrections), which no captured frame has. Positions are ignored:
    the added frame copies the first captured root position.

    ``atol`` (degrees) is how far from a whole degree a rotation may be: 0 for a BVH, whose
    numbers are as written; an FBX's rotations come back through Blender's float32 matrices
    (:mod:`motionlib.io.fbx`), a few 1e-5 degrees off.
    """
    if channels.shape[0] < 2:
        return None
    starts = skeleton.channel_starts
    cols = [starts[j] + k for j, names in enumerate(skeleton.channels)
            for k, name in enumerate(names) if name in ROTATION_CHANNELS]
    if not cols:
        return None
    first = channels[0, cols]
    whole = np.all(np.abs(first - np.round(first)) <= atol)
    mostly_zero = np.mean(np.abs(first) <= atol) >= 0.75
    moves = np.abs(first - channels[1, cols]).max() > atol
    return 0 if whole and mostly_zero and moves else None


def _snap_fps(frame_time: float) -> float:
    fps = 1.0 / frame_time
    whole = round(fps)
    return float(whole) if whole > 0 and abs(fps - whole) <= 1e-3 * fps else fps


def read_bvh(path: str | os.PathLike, *, limits: Limits = DEFAULT_LIMITS) -> Take:
    """Read a BVH file.

    Parameters
    ----------
    path : str or PathLike
    limits : Limits, optional
        Joints, frames and sizes to refuse; checked before the frames are allocated.

    Returns
    -------
    Take
        ``format == "bvh"``; ``channels`` shape (n_frames, n_channels) as stored in the file.

    Raises
    ------
    CaptureError
        Naming the file, the line and what was wrong.
    """
    path = os.fspath(path)
    data = read_lines_bytes(path)
    skeleton, n_frames, frame_time, pos, line = _head(data, len(data), path, limits)
    channels = _parse_motion(data, pos, line, n_frames, skeleton, path, limits)
    del data
    return Take(name=Path(path).stem, format="bvh", fps=_snap_fps(frame_time),
                frame_time=frame_time, channels=channels, skeleton=skeleton,
                rest_pose_frame=detect_rest_pose(skeleton, channels), path=path)


def _head(data: bytes, file_bytes: int, path, limits: Limits):
    """The HIERARCHY and the motion header at the start of ``data``, checked against
    ``limits`` for a file of ``file_bytes``: (skeleton, n_frames, frame_time, body byte,
    body line)."""
    if _NOT_BLANK.search(data) is None:  # not data.strip(): that copies a whole hour of text
        raise CaptureError("empty file", path=path, line=1)
    m = _MOTION.search(data)
    header = data[:m.start()] if m else data
    skeleton = parse_hierarchy(header.decode("utf-8-sig", "replace"), path, limits=limits)
    if m is None:
        raise CaptureError("no MOTION section after the HIERARCHY", path=path,
                           line=header.count(b"\n") + 1)
    motion_line = header.count(b"\n") + 1
    n_frames, frame_time, pos, line, frames_line = _motion_header(data, m.end(), motion_line,
                                                                  path, limits)
    check_size(n_frames, skeleton.n_joints, skeleton.n_channels, file_bytes, limits,
               path=path, line=frames_line)
    return skeleton, n_frames, frame_time, pos, line


def _has_motion_header(data: bytes) -> bool:
    """Whether ``data`` holds MOTION and, after it, three whole lines that are not blank
    (``Frames:``, ``Frame Time:`` and the first frame)."""
    m = _MOTION.search(data)
    whole = data[m.end():].split(b"\n")[1:-1] if m else []
    return sum(1 for line in whole if line.strip()) >= 3


# A BVH's hierarchy and motion header fit in the first block of nearly every file.
HEAD_BLOCK = 1 << 16


def check_bvh(path: str | os.PathLike, *, limits: Limits = DEFAULT_LIMITS) -> tuple[Skeleton, int, float]:
    """Check a BVH file's structure without reading its frames.

    Reads the file up to the line after ``Frame Time:`` only (a few kilobytes of a file
    of any size), and checks what ``read_bvh`` checks there: the HIERARCHY, the
    ``Frames:`` and ``Frame Time:`` lines, and the frame count against ``limits`` for
    the file's size. A bad frame value or a missing frame line is not seen: ``read_bvh``
    finds it and names its line.

    Returns
    -------
    skeleton : Skeleton
    n_frames : int
    frame_time : float, seconds

    Raises
    ------
    CaptureError
        Naming the file, the line and what was wrong, with ``read_bvh``'s messages.
    """
    path = os.fspath(path)
    file_bytes = os.path.getsize(path)
    with open(path, "rb") as fh:
        data = b""
        while True:
            block = fh.read(HEAD_BLOCK)
            data = lone_cr_to_lf(data + block)
            if not block or _has_motion_header(data):
                break
    skeleton, n_frames, frame_time, _, _ = _head(data, file_bytes, path, limits)
    return skeleton, n_frames, frame_time


_ROOT_CHANNELS = ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
_JOINT_CHANNELS = ("Zrotation", "Yrotation", "Xrotation")


def bvh_layout(take: Take) -> tuple[Skeleton, np.ndarray]:
    """The take's skeleton and channels in a form BVH can hold.

    A BVH take is returned as is. An ASF/AMC take's local rotations ``C @ M @ C.T`` are
    re-expressed as ``Zrotation Yrotation Xrotation`` Euler angles (root: positions first), so
    forward kinematics of the result equals that of the take.

    Returns
    -------
    skeleton : Skeleton
    channels : ndarray, shape (n_frames, n_channels)
    """
    from motionlib.kinematics import euler_to_matrix, matrix_to_euler_zyx

    sk = take.skeleton
    if sk.axes is None:
        return sk, take.channels
    starts, n = sk.channel_starts, take.n_frames
    blocks, layout = [], []
    for j, names in enumerate(sk.channels):
        col = {name: take.channels[:, starts[j] + k] for k, name in enumerate(names)}
        order = sk.rotation_orders[j]
        angles = np.stack([col.get(f"{a}rotation", np.zeros(n)) for a in order], axis=1)
        local = sk.axes[j] @ euler_to_matrix(angles, order) @ sk.axes[j].T
        euler = matrix_to_euler_zyx(local)
        if j == 0:
            pos = np.stack([col.get(f"{a}position", np.full(n, sk.offsets[0][i]))
                            for i, a in enumerate("XYZ")], axis=1)
            blocks.append(np.hstack([pos, euler]))
            layout.append(_ROOT_CHANNELS)
        else:
            blocks.append(euler)
            layout.append(_JOINT_CHANNELS)
    skeleton = Skeleton(names=list(sk.names), parents=sk.parents.copy(),
                        offsets=sk.offsets.copy(), channels=layout,
                        rotation_orders=["ZYX"] * sk.n_joints, end_sites=dict(sk.end_sites))
    return skeleton, np.hstack(blocks)


def _fmt(values) -> str:
    return " ".join(f"{v:.6f}" for v in values)


def _hierarchy_lines(sk: Skeleton) -> list[str]:
    """The HIERARCHY's joint blocks, written with a stack (a chain of 1,000 joints is fine)."""
    children = sk.children_lists()
    lines: list[str] = []
    stack: list[tuple[int, int, bool]] = [(0, 0, False)]  # (joint, depth, closing)
    while stack:
        j, depth, closing = stack.pop()
        pad = "\t" * depth
        if closing:
            if j in sk.end_sites:
                lines += [f"{pad}\tEnd Site", f"{pad}\t{{",
                          f"{pad}\t\tOFFSET {_fmt(sk.end_sites[j])}", f"{pad}\t}}"]
            lines.append(f"{pad}}}")
            continue
        keyword = "ROOT" if j == 0 else "JOINT"
        lines += [f"{pad}{keyword} {sk.names[j]}", f"{pad}{{",
                  f"{pad}\tOFFSET {_fmt(sk.offsets[j])}"]
        if sk.channels[j] or j == 0:
            lines.append(f"{pad}\tCHANNELS {len(sk.channels[j])} "
                         f"{' '.join(sk.channels[j])}".rstrip())
        stack.append((j, depth, True))
        stack += [(c, depth + 1, False) for c in reversed(children[j])]
    return lines


def write_bvh(take: Take, path_or_textfile, *, start: int | None = None,
              stop: int | None = None) -> None:
    """Write frames ``start`` (0-based) to ``stop`` (exclusive) of a take as BVH.

    The hierarchy and frame time are the take's own; values are written with 6 decimals.
    An ASF/AMC take is converted (see :func:`bvh_layout`); its forward kinematics is unchanged.

    Parameters
    ----------
    take : Take
    path_or_textfile : str, PathLike or a text file object with ``write``
    start, stop : int, optional
        Frame range; the whole take by default.
    """
    if take.skeleton.point_set:
        raise CaptureError("a take of points (markers or tracked joints) has no joint "
                           "rotations to write as BVH; write it as C3D or CSV", path=take.path)
    start, stop = frame_range(take.n_frames, start, stop) if take.n_frames else (0, 0)
    skeleton, channels = bvh_layout(take)
    head = ["HIERARCHY", *_hierarchy_lines(skeleton), "MOTION",
            f"Frames: {stop - start}", f"Frame Time: {take.frame_time:.10g}"]
    body = "\n".join(_fmt(row) for row in channels[start:stop])
    text = "\n".join(head) + "\n" + body + ("\n" if body else "")
    if hasattr(path_or_textfile, "write"):
        path_or_textfile.write(text)
    else:
        Path(path_or_textfile).write_text(text, encoding="utf-8", newline="\n")
