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

from motionlib.errors import CaptureError
from motionlib.io.numbers import finite_value, read_rows
from motionlib.skeleton import CHANNEL_NAMES, ROTATION_CHANNELS, Skeleton
from motionlib.take import Take, frame_range

_CHANNEL_BY_LOWER = {c.lower(): c for c in CHANNEL_NAMES}
_MOTION = re.compile(rb"^[ \t]*MOTION\b", re.MULTILINE | re.IGNORECASE)


def _short(token: str) -> str:
    """A token for an error message: quoted, and cut if it is binary junk or very long."""
    return repr(token if len(token) <= 40 else token[:40] + "...")


class _Tokens:
    """The HIERARCHY as a stream of (token, line number), braces split off."""

    def __init__(self, text: str, path):
        self.items = [(tok, n) for n, line in enumerate(text.splitlines(), 1)
                      for tok in line.replace("{", " { ").replace("}", " } ").split()]
        self.path = path
        self.pos = 0
        self.last_line = max(1, text.count("\n") + 1)

    def error(self, message: str, line: int | None = None) -> CaptureError:
        if line is None:
            line = self.items[self.pos][1] if self.pos < len(self.items) else self.last_line
        return CaptureError(message, path=self.path, line=line)

    def peek(self) -> str | None:
        return self.items[self.pos][0] if self.pos < len(self.items) else None

    def next(self, what: str) -> tuple[str, int]:
        if self.pos >= len(self.items):
            raise self.error(f"unexpected end of HIERARCHY, expected {what}")
        self.pos += 1
        return self.items[self.pos - 1]

    def expect(self, keyword: str) -> None:
        tok, line = self.next(repr(keyword))
        if tok.upper() != keyword.upper():
            raise self.error(f"expected {keyword!r}, found {_short(tok)}", line)

    def number(self, what: str) -> float:
        tok, line = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise self.error(f"{what} must be a number, found {_short(tok)}", line) from None
        if not math.isfinite(value):
            raise self.error(f"{what} must be finite, found {_short(tok)}", line)
        return value


class _Builder:
    def __init__(self):
        self.names, self.parents, self.offsets, self.channels = [], [], [], []
        self.end_sites: dict[int, np.ndarray] = {}


def _parse_joint(tokens: _Tokens, b: _Builder, parent: int) -> None:
    name, line = tokens.next("a joint name")
    if name in ("{", "}"):
        raise tokens.error(f"missing joint name before {name!r}", line)
    if name in b.names:
        raise tokens.error(f"duplicate joint name {name!r}", line)
    j = len(b.names)
    b.names.append(name)
    b.parents.append(parent)
    tokens.expect("{")
    tokens.expect("OFFSET")
    b.offsets.append([tokens.number(f"OFFSET of {name}") for _ in range(3)])
    b.channels.append(_parse_channels(tokens, name) if tokens.peek() == "CHANNELS" else ())
    while True:
        tok, line = tokens.next(f"JOINT, End Site or '}}' closing {name}")
        if tok == "}":
            return
        if tok.upper() == "JOINT":
            _parse_joint(tokens, b, j)
        elif tok.upper() == "END":
            _parse_end_site(tokens, b, j)
        else:
            raise tokens.error(f"unexpected {_short(tok)} in joint {name}", line)


def _parse_channels(tokens: _Tokens, name: str) -> tuple[str, ...]:
    tokens.next("CHANNELS")
    tok, line = tokens.next("a channel count")
    if not tok.isdigit() or int(tok) > 6:
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
    b.end_sites[j] = np.array([tokens.number(f"End Site OFFSET of {b.names[j]}")
                               for _ in range(3)])
    tokens.expect("}")


def parse_hierarchy(text: str, path=None) -> Skeleton:
    """Skeleton from the HIERARCHY section of a BVH file (everything before ``MOTION``)."""
    tokens = _Tokens(text, path)
    if not tokens.items:
        raise tokens.error("empty HIERARCHY")
    tokens.expect("HIERARCHY")
    tokens.expect("ROOT")
    b = _Builder()
    _parse_joint(tokens, b, -1)
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


def _motion_header(data: bytes, pos: int, line: int, path) -> tuple[int, float, int, int]:
    """Parse ``Frames:`` and ``Frame Time:``; return (n_frames, frame_time, body byte, body line)."""
    text, line, pos = _next_line(data, pos, line)
    m = re.fullmatch(r"Frames:\s*(\S+)", text, re.IGNORECASE)
    if not m:
        raise CaptureError(f"expected 'Frames: <count>' after MOTION, found {text[:40]!r}",
                           path=path, line=line)
    if not m.group(1).isdigit():
        raise CaptureError(f"frame count must be a whole number, found {m.group(1)!r}",
                           path=path, line=line)
    n_frames = int(m.group(1))
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
                           f"{m.group(1)!r}", path=path, line=line)
    return n_frames, frame_time, pos, line + 1


def _parse_motion(data: bytes, pos: int, line: int, n_frames: int, n_channels: int,
                  path) -> np.ndarray:
    """Frame values as (n_frames, n_channels); ``line`` is the line number of byte ``pos``."""
    values = read_rows(data, pos, n_frames, n_channels)
    if values is not None:
        return values
    # Slow path: nan, no channels, or something wrong that needs a line number.
    return _parse_motion_lines(data[pos:].decode("utf-8", "replace"), line, n_frames,
                               n_channels, path)


def _parse_motion_lines(text: str, first_line: int, n_frames: int, n_channels: int,
                        path) -> np.ndarray:
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
        rows.append([finite_value(tok, f"frame {len(rows)}, value {k + 1}: ", "", path, last)
                     for k, tok in enumerate(tokens)])
    if len(rows) < n_frames:
        raise CaptureError(f"truncated MOTION section: 'Frames: {n_frames}' but the file ends "
                           f"after {len(rows)} frame lines", path=path, line=last)
    return np.array(rows, dtype=np.float64).reshape(n_frames, n_channels)


def detect_rest_pose(skeleton: Skeleton, channels: np.ndarray) -> int | None:
    """Index of an added rest (T-) pose at the start of a take, or None.

    Converters such as cgspeed's prepend a frame whose rotations are whole degrees, nearly all
    zero (a few fixed limb corrections), which no captured frame has. Positions are ignored:
    the added frame copies the first captured root position.
    """
    if channels.shape[0] < 2:
        return None
    starts = skeleton.channel_starts
    cols = [starts[j] + k for j, names in enumerate(skeleton.channels)
            for k, name in enumerate(names) if name in ROTATION_CHANNELS]
    if not cols:
        return None
    first = channels[0, cols]
    whole = np.all(first == np.round(first))
    mostly_zero = np.mean(first == 0) >= 0.75
    return 0 if whole and mostly_zero and not np.array_equal(first, channels[1, cols]) else None


def _snap_fps(frame_time: float) -> float:
    fps = 1.0 / frame_time
    whole = round(fps)
    return float(whole) if whole > 0 and abs(fps - whole) <= 1e-3 * fps else fps


def read_bvh(path: str | os.PathLike) -> Take:
    """Read a BVH file.

    Parameters
    ----------
    path : str or PathLike

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
    data = Path(path).read_bytes()
    if not data.strip():
        raise CaptureError("empty file", path=path, line=1)
    m = _MOTION.search(data)
    header = data[:m.start()] if m else data
    skeleton = parse_hierarchy(header.decode("utf-8-sig", "replace"), path)
    if m is None:
        raise CaptureError("no MOTION section after the HIERARCHY", path=path,
                           line=header.count(b"\n") + 1)
    motion_line = header.count(b"\n") + 1
    n_frames, frame_time, pos, line = _motion_header(data, m.end(), motion_line, path)
    channels = _parse_motion(data, pos, line, n_frames, skeleton.n_channels, path)
    del data
    return Take(name=Path(path).stem, format="bvh", fps=_snap_fps(frame_time),
                frame_time=frame_time, channels=channels, skeleton=skeleton,
                rest_pose_frame=detect_rest_pose(skeleton, channels), path=path)


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


def _hierarchy_lines(sk: Skeleton, j: int, depth: int) -> list[str]:
    pad = "\t" * depth
    keyword = "ROOT" if j == 0 else "JOINT"
    lines = [f"{pad}{keyword} {sk.names[j]}", f"{pad}{{", f"{pad}\tOFFSET {_fmt(sk.offsets[j])}"]
    if sk.channels[j] or j == 0:
        lines.append(f"{pad}\tCHANNELS {len(sk.channels[j])} {' '.join(sk.channels[j])}".rstrip())
    for child in sk.children(j):
        lines += _hierarchy_lines(sk, child, depth + 1)
    if j in sk.end_sites:
        lines += [f"{pad}\tEnd Site", f"{pad}\t{{",
                  f"{pad}\t\tOFFSET {_fmt(sk.end_sites[j])}", f"{pad}\t}}"]
    lines.append(f"{pad}}}")
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
    start, stop = frame_range(take.n_frames, start, stop) if take.n_frames else (0, 0)
    skeleton, channels = bvh_layout(take)
    head = ["HIERARCHY", *_hierarchy_lines(skeleton, 0, 0), "MOTION",
            f"Frames: {stop - start}", f"Frame Time: {take.frame_time:.10g}"]
    body = "\n".join(_fmt(row) for row in channels[start:stop])
    text = "\n".join(head) + "\n" + body + ("\n" if body else "")
    if hasattr(path_or_textfile, "write"):
        path_or_textfile.write(text)
    else:
        Path(path_or_textfile).write_text(text, encoding="utf-8", newline="\n")
