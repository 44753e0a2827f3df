"""C3D marker files: read into a :class:`~motionlib.points.PointTake`, write a (trimmed) take.

The header and the parameter section (groups, parameters, processor type, Intel / DEC /
MIPS number formats) are read by the ``c3d`` package: pure Python on numpy, a small parser
of a few kilobytes of parameters, and a writer that builds a valid parameter section. The
frames, the bulk of a file, are decoded here in one numpy view of the data section (int16
scaled by ``POINT:SCALE``, or float32 when it is negative) rather than by ``c3d``'s
frame-by-frame loop, so reading costs about what copying the numbers costs.

Gaps: a point whose residual word is negative (the C3D convention for "not seen"), or
whose coordinates are not finite, is NaN. Written files mark gaps the same way (residual
-1, coordinates 0). Analog channels are skipped on reading and not written.
"""

from __future__ import annotations

import io
import os
import struct
import warnings
from pathlib import Path

import numpy as np

from motionlib.errors import CaptureError, shorten
from motionlib.points import PointTake, make_point_take
from motionlib.take import DEFAULT_LIMITS, Limits, check_points, check_size, frame_range

BLOCK = 512
C3D_KEY = 0x50
PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS"}


def _c3d():
    import c3d

    return c3d


def _parameters_reader():
    """``c3d.Reader`` that takes the parameter section as it is.

    The header repeats a few parameters (point count, scale, rate) for old programs; the
    C3D specification makes the parameters authoritative, and writers do leave the two
    apart (a header rate of 120.5 beside ``POINT:RATE`` 120). ``c3d`` refuses such a file
    with an assertion; everything read here comes from the parameters.
    """
    class Reader(_c3d().Reader):
        def _check_metadata(self):
            pass

    return Reader


def read_c3d(path: str | os.PathLike, *, limits: Limits = DEFAULT_LIMITS) -> PointTake:
    """Read the 3D points of a C3D file.

    Returns
    -------
    PointTake
        ``format == "c3d"``; points named by ``POINT:LABELS`` (blank labels become
        ``point<n>``, a repeated label gets ``#<n>``), ``fps`` from ``POINT:RATE``, unit
        from ``POINT:UNITS`` (mm when absent), Z up unless ``POINT:Y_SCREEN`` says ``+Y``,
        ``first_number`` the header's first frame.

    Raises
    ------
    CaptureError
        Naming the file and the header word, parameter or data block at fault.
    """
    path = os.fspath(path)
    data = Path(path).read_bytes()
    reader = _reader(data, path)
    layout = _layout(reader, data, path, limits)
    coordinates = _frames(data, layout, path)
    _check_lengths(coordinates, layout, limits, path)
    labels = _labels(reader, layout["n_points"])
    units = _string(reader, "POINT:UNITS") or "mm"
    y_screen = (_string(reader, "POINT:Y_SCREEN") or "+Z").upper()
    return make_point_take(name=Path(path).stem, format="c3d", fps=layout["rate"],
                           coordinates=coordinates, names=labels, unit=units,
                           up="y" if y_screen.endswith("Y") else "z",
                           first_number=layout["first"], path=path)


def _reader(data: bytes, path):
    if len(data) < BLOCK:
        raise CaptureError(f"header block 1: the file has {len(data)} bytes, a C3D header "
                           f"needs {BLOCK}", path=path)
    parameter_block, key = data[0], data[1]
    if key != C3D_KEY:
        raise CaptureError(f"header block 1, byte 2: {key:#04x} is not the C3D key 0x50; "
                           "not a C3D file", path=path)
    if parameter_block < 2 or parameter_block * BLOCK > len(data):
        raise CaptureError(f"header block 1, byte 1: the parameter section starts at block "
                           f"{parameter_block}, the file has {len(data) // BLOCK} blocks",
                           path=path)
    processor = data[(parameter_block - 1) * BLOCK + 3]
    if processor not in PROCESSORS:
        raise CaptureError(f"parameter block {parameter_block}, byte 4: processor type "
                           f"{processor} is not 84 (Intel), 85 (DEC) or 86 (MIPS)", path=path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return _parameters_reader()(io.BytesIO(data))
    except (struct.error, ValueError, KeyError, IndexError, TypeError, AttributeError,
            UnicodeDecodeError, OverflowError, AssertionError) as exc:
        raise CaptureError(f"parameter section (from block {parameter_block}): cannot be "
                           f"read ({shorten(exc, 120)})", path=path) from None


def _param(reader, name: str):
    try:
        return reader.get(name)
    except (KeyError, ValueError, AttributeError):
        return None


def _string(reader, name: str) -> str | None:
    """A parameter's text, None when it is absent or not text (both optional here)."""
    param = _param(reader, name)
    if param is None:
        return None
    try:
        value = param.string_value
    except (ValueError, UnicodeDecodeError, IndexError, struct.error):
        return None
    return value.strip() or None if isinstance(value, str) else None


def _number(reader, name: str, path, kind: str):
    param = _param(reader, name)
    if param is None:
        raise CaptureError(f"parameter {name} is missing", path=path)
    try:
        if kind == "float":
            value = param.float_value
        else:  # counts are unsigned 16-bit words (C3D allows up to 65535 points)
            value = param.uint16_value if param.bytes_per_element == 2 else \
                param._as_integer_value
    except (struct.error, ValueError, IndexError, TypeError):
        raise CaptureError(f"parameter {name}: not a number ({param.bytes_per_element} "
                           "bytes per element)", path=path) from None
    return value


def _layout(reader, data: bytes, path, limits: Limits) -> dict:
    header = reader.header
    n_points = int(_number(reader, "POINT:USED", path, "int"))
    if n_points < 1:
        raise CaptureError(f"parameter POINT:USED is {n_points}; the file has no 3D points",
                           path=path)
    check_points(n_points, limits, path=path, what="points (parameter POINT:USED)")
    scale = float(_number(reader, "POINT:SCALE", path, "float"))
    if not np.isfinite(scale) or scale == 0:
        raise CaptureError(f"parameter POINT:SCALE is {scale}; it must be a non-zero number",
                           path=path)
    rate = float(_number(reader, "POINT:RATE", path, "float"))
    if not np.isfinite(rate) or not 1 / limits.max_frame_time <= rate <= 1 / limits.min_frame_time:
        raise CaptureError(f"parameter POINT:RATE is {rate}; frames per second must be between "
                           f"{1 / limits.max_frame_time:g} and {1 / limits.min_frame_time:g}",
                           path=path)
    try:
        first, last = int(reader.first_frame), int(reader.last_frame)
    except (struct.error, ValueError, IndexError, TypeError, OverflowError) as exc:
        raise CaptureError("header words 4-5 and parameters TRIAL:ACTUAL_START_FIELD, "
                           "TRIAL:ACTUAL_END_FIELD, POINT:LONG_FRAMES, POINT:FRAMES: the frame range "
                           f"cannot be read ({shorten(exc, 80)})", path=path) from None
    n_frames = last - first + 1
    if n_frames < 0:
        raise CaptureError(f"header: the last frame {last} comes before the first {first}",
                           path=path)
    check_size(n_frames, n_points, 3 * n_points, len(data), limits, path=path)
    is_float = scale < 0
    word = 4 if is_float else 2
    try:
        analog = int(reader.analog_used) * int(reader.analog_per_frame)
    except (struct.error, ValueError, IndexError, TypeError, OverflowError) as exc:
        raise CaptureError("parameters ANALOG:USED, ANALOG:RATE: the analog channels per "
                           f"frame cannot be read ({shorten(exc, 80)})", path=path) from None
    data_block = int(header.data_block)
    start = (data_block - 1) * BLOCK
    if data_block < 2 or start > len(data):
        raise CaptureError(f"header word 9: the data section starts at block {data_block}, "
                           f"the file has {len(data) // BLOCK} blocks", path=path)
    return {"n_points": n_points, "scale": scale, "rate": rate, "first": first,
            "n_frames": n_frames, "is_float": is_float, "word": word, "start": start,
            "frame_words": 4 * n_points + analog, "data_block": data_block,
            "processor": PROCESSORS[data[(header.parameter_block - 1) * BLOCK + 3]]}


def _frames(data: bytes, layout: dict, path) -> np.ndarray:
    """Coordinates (n_frames, n_points, 3) float64, NaN where a point was not seen."""
    n, p, words = layout["n_frames"], layout["n_points"], layout["frame_words"]
    frame_bytes = words * layout["word"]
    available = (len(data) - layout["start"]) // frame_bytes if frame_bytes else 0
    if available < n:
        raise CaptureError(f"data section (from block {layout['data_block']}): the file ends "
                           f"in frame {available + 1} of the {n} frames the header declares",
                           path=path)
    raw = data[layout["start"]: layout["start"] + n * frame_bytes]
    big = layout["processor"] == "MIPS"
    if layout["is_float"]:
        if layout["processor"] == "DEC":
            values = _c3d().DEC_to_IEEE_BYTES(raw).reshape(n, words)
        else:
            values = np.frombuffer(raw, dtype=">f4" if big else "<f4").reshape(n, words)
        points = values[:, : 4 * p].reshape(n, p, 4)
        with np.errstate(invalid="ignore"):  # NaN words are gaps, marked below
            xyz = points[..., :3].astype(np.float64)
        residual = _residual_of_float(points[..., 3])
    else:
        values = np.frombuffer(raw, dtype=">i2" if big else "<i2").reshape(n, words)
        points = values[:, : 4 * p].reshape(n, p, 4)
        xyz = points[..., :3] * abs(layout["scale"])
        residual = points[..., 3].astype(np.int32)
    # A sum is not finite when any term is not (inf - inf is NaN); far cheaper than a
    # reduction over an axis of three.
    gap = (residual < 0) | ~np.isfinite(xyz[..., 0] + xyz[..., 1] + xyz[..., 2])
    xyz[gap] = np.nan
    return xyz


def _check_lengths(xyz: np.ndarray, layout: dict, limits: Limits, path) -> None:
    """Refuse a coordinate beyond ``limits.max_length`` (int16 words times a POINT:SCALE of
    1e38 are finite here and infinite as float32 positions), naming frame, point and value."""
    with np.errstate(invalid="ignore"):
        beyond = np.abs(xyz) > limits.max_length
    frames = np.flatnonzero(beyond.any(axis=(1, 2)))
    if len(frames):
        frame = int(frames[0])
        point = int(np.flatnonzero(beyond[frame].any(axis=1))[0])
        value = float(xyz[frame, point][beyond[frame, point]][0])
        raise CaptureError(f"data section, frame {layout['first'] + frame}, point {point + 1}: "
                           f"{value:g} is beyond the largest coordinate a take may hold "
                           f"(±{limits.max_length:g})", path=path)


def _residual_of_float(word: np.ndarray) -> np.ndarray:
    """The residual word of float data is an integer stored as a float; NaN counts as a gap."""
    with np.errstate(invalid="ignore"):
        return np.where(np.isfinite(word), word, -1).astype(np.int64)


def _labels(reader, n_points: int) -> list[str]:
    labels: list[str] = []
    for name in ("POINT:LABELS", *(f"POINT:LABELS{k}" for k in range(2, 100))):
        param = _param(reader, name)
        if param is None:
            break
        try:
            labels.extend(str(v).strip() for v in np.atleast_1d(param.string_array))
        except (ValueError, UnicodeDecodeError, IndexError):
            break
    labels = labels[:n_points] + [""] * max(0, n_points - len(labels))
    named, seen = [], {}
    for i, label in enumerate(labels):
        label = label or f"point{i + 1}"
        seen[label] = seen.get(label, 0) + 1
        named.append(label if seen[label] == 1 else f"{label}#{seen[label]}")
    return named


# A C3D parameter's dimensions are bytes: at most 255 labels per LABELS parameter, of at most
# 255 characters each. More points go on in LABELS2, LABELS3... (as the reader reads them).
LABELS_PER_PARAMETER = 255


def _set_labels(writer, c3d, names: list[str]) -> None:
    """POINT:LABELS (then LABELS2...) and POINT:DESCRIPTIONS for any number of points;
    ``c3d.Writer.set_point_labels`` writes one parameter, which cannot hold 256."""
    names = [name[:LABELS_PER_PARAMETER] for name in names]
    for k in range(0, len(names), LABELS_PER_PARAMETER):
        chunk = names[k:k + LABELS_PER_PARAMETER]
        text, size = c3d.Writer.pack_labels(chunk)
        suffix = "" if k == 0 else str(k // LABELS_PER_PARAMETER + 1)
        writer.point_group.add_str(f"LABELS{suffix}", "Point labels.", text, size, len(chunk))
    described = min(len(names), LABELS_PER_PARAMETER)
    writer.point_group.add_str("DESCRIPTIONS", "Channel descriptions.", " " * described, 1,
                               described)


def write_c3d(take: PointTake, out, *, start: int | None = None,
              stop: int | None = None) -> None:
    """Write frames ``[start, stop)`` of a point take as a C3D file (float, Intel).

    The same points (labels), rate, unit and up axis (``POINT:Y_SCREEN``) as the take; the
    header's first frame is the file number of ``start``; gaps are written as C3D gaps.
    Coordinates are float32, as C3D stores them (a take read from C3D is written exactly).

    Parameters
    ----------
    out : str, PathLike or binary file object
    """
    start, stop = frame_range(take.n_frames, start, stop)
    c3d = _c3d()
    writer = c3d.Writer(point_rate=float(take.fps), point_units=f"{take.unit:<4}")
    _set_labels(writer, c3d, list(take.point_names))
    writer.set_start_frame(int(take.first_number + start))
    xyz = take.channels[start:stop].reshape(stop - start, take.n_points, 3)
    gap = np.isnan(xyz).any(axis=-1)
    frames = np.zeros((stop - start, take.n_points, 5), dtype=np.float32)
    frames[..., :3] = np.where(gap[..., None], 0.0, xyz)
    frames[..., 3] = np.where(gap, -1.0, 0.0)
    empty = np.zeros((0, 0))
    writer.add_frames([(frame, empty) for frame in frames])
    writer.set_screen_axis(X="+X", Y="+Y" if take.up == "y" else "+Z")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if hasattr(out, "write"):
            writer.write(out)
        else:
            with open(out, "wb") as handle:
                writer.write(handle)
