"""Joint-position CSV: Cutroom's plain layout for points over time (markerless trackers,
depth cameras, anything that exports positions).

Layout (comma-separated, one header line, then one row per frame)::

    # fps=30 unit=m up=y                      <- optional; these are the defaults
    frame,hip_center_x,hip_center_y,hip_center_z,spine_x,spine_y,spine_z,...
    190,0.807139,-0.063421,1.998671,0.810986,-0.005124,1.992173,...

- The first column is ``frame`` (or ``frame_id``): whole frame numbers on a clock of
  ``fps``, rising; a number may be skipped (nothing tracked then: a gap in every point) or
  repeated (the first row counts). Or it is ``time``: seconds; each row goes to frame
  ``round((t - t0) * fps)``, with ``fps`` from the comment line or else one over the median
  time step.
- Then three columns per point, ``<point>_x``, ``<point>_y``, ``<point>_z``, in that order.
  An empty cell (or ``nan``) is a point not seen.
- ``# key=value`` lines before the header may give ``fps`` (frames per second), ``unit``
  (length unit, ``m`` by default) and ``up`` (``y`` by default, as Kinect camera space;
  ``z`` for Z-up data).

The UTKinect skeleton files follow it with ``frame_id`` on the Kinect's 30 Hz clock.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

import numpy as np

from motionlib.errors import CaptureError, shorten
from motionlib.io.pointtext import (
    MAX_FRAME_NUMBER,
    check_coordinates,
    frame_numbers,
    on_clock,
    parse_cells,
)
from motionlib.io.text import read_lines_bytes, spreadsheet_safe, spreadsheet_text
from motionlib.points import UP_AXES, PointTake, make_point_take
from motionlib.take import (
    DEFAULT_LIMITS,
    Limits,
    check_point_names,
    check_points,
    check_size,
    frame_range,
    max_frames_for,
)

DEFAULTS = {"fps": "30", "unit": "m", "up": "y"}
FRAME_COLUMNS = ("frame", "frame_id")


def read_points_csv(path: str | os.PathLike, *, limits: Limits = DEFAULT_LIMITS) -> PointTake:
    """Read a joint-position CSV (see the module docstring for the layout).

    Returns
    -------
    PointTake
        ``format == "csv"``; ``first_number`` the first row's frame number (``frame``
        columns) or 0 (``time``).

    Raises
    ------
    CaptureError
        At ``file:line``, naming the column or setting at fault.
    """
    path = os.fspath(path)
    data = read_lines_bytes(path)
    settings, offset, line = _settings(data, path)
    columns, names, offset = _header(data, offset, line, path, limits)
    values, lines = parse_cells(data, offset, len(columns), ",", path, columns)
    check_size(len(values), len(names), 3 * len(names), len(data), limits, path=path)
    check_coordinates(values, 1, lines, columns, limits.max_length, path)
    rows = values[:, 1:].reshape(len(values), len(names), 3)
    if columns[0] == "time":
        fps, numbers = _time_clock(values[:, 0], lines, settings, path)
        first_number = 0
    else:
        fps = _fps(settings, path)
        numbers = frame_numbers(values, lines, columns[0], path)
        first_number = int(numbers[0]) if len(numbers) else 0
    coordinates = on_clock(numbers, rows, max_frames_for(
        len(names), 3 * len(names), len(data), limits), path)
    return make_point_take(name=Path(path).stem, format="csv", fps=fps,
                           coordinates=coordinates, names=names, unit=settings["unit"],
                           up=settings["up"], first_number=first_number, path=path)


def _settings(data: bytes, path) -> tuple[dict[str, str], int, int]:
    settings, pos, line = dict(DEFAULTS), 0, 0
    given: set[str] = set()
    while pos < len(data) and data[pos:pos + 1] in (b"#", b"\n", b"\r"):
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end
        text = data[pos:end].decode("utf-8", "replace").lstrip("#").strip()
        for item in text.replace(",", " ").split():
            key, sep, value = item.partition("=")
            if not sep or key not in DEFAULTS:
                raise CaptureError(f"setting {shorten(item)}: expected fps=, unit= or up=",
                                   path=path, line=line + 1)
            settings[key] = value
            given.add(key)
        pos, line = end + 1, line + 1
    settings["fps_given"] = "fps" in given
    if settings["up"].lower() not in UP_AXES:
        raise CaptureError(f"setting up={shorten(settings['up'])}: expected y or z", path=path)
    settings["up"] = settings["up"].lower()
    return settings, pos, line


def _header(data: bytes, offset: int, line: int, path, limits: Limits):
    """The column names, the point names and the byte after the header line.

    Linear in the line's length (a header of 300,000 columns is read in milliseconds), and
    a header of more points than ``limits.max_joints`` is refused before its names are."""
    end = data.find(b"\n", offset)
    end = len(data) if end < 0 else end
    columns = header_cells(data[offset:end].decode("utf-8", "replace"))
    if not columns or columns[0].lower() not in (*FRAME_COLUMNS, "time"):
        raise CaptureError(f"column 1: {shorten(columns[0] if columns else '')} should be "
                           "frame, frame_id or time", path=path, line=line + 1)
    columns[0] = columns[0].lower()
    if len(columns) < 4 or (len(columns) - 1) % 3:
        raise CaptureError(f"expected the first column and three per point "
                           f"(<point>_x, <point>_y, <point>_z), found {len(columns)} columns",
                           path=path, line=line + 1)
    check_points((len(columns) - 1) // 3, limits, path=path, line=line + 1)
    names: list[str] = []
    given: set[str] = set()  # a set: a list's ``in`` made long headers quadratic
    for k in range(1, len(columns), 3):
        point = columns[k][:-2]
        for i, axis in enumerate("xyz"):
            if columns[k + i].lower() != f"{point}_{axis}".lower() or not point:
                raise CaptureError(f"column {k + i + 1}: {shorten(columns[k + i])} should be "
                                   f"{point or '<point>'}_{axis}", path=path, line=line + 1)
        if point in given:
            raise CaptureError(f"column {k + 1}: point {shorten(point)} is given twice",
                               path=path, line=line + 1)
        names.append(point)
        given.add(point)
    check_point_names(names, limits, path=path, line=line + 1)
    return columns, names, end + 1


def header_cells(line: str) -> list[str]:
    """The column names of a header line, as CSV quotes them (a point named ``a,b`` is
    ``"a,b_x"``) and as :func:`write_points_csv` protects them (``'=x_x`` is ``=x_x``)."""
    cells = next(csv.reader([line]), [""])
    return [spreadsheet_text(c.strip()) for c in cells] or [""]


def _fps(settings, path) -> float:
    try:
        fps = float(settings["fps"])
    except ValueError:
        raise CaptureError(f"setting fps={shorten(settings['fps'])} is not a number",
                           path=path, line=1) from None
    if not 0.1 <= fps <= 10000:
        raise CaptureError(f"setting fps={fps:g} is outside 0.1 to 10000", path=path, line=1)
    return fps


def _time_clock(times, lines, settings, path) -> tuple[float, np.ndarray]:
    bad = np.flatnonzero(np.isnan(times))
    if len(bad):
        raise CaptureError("column 1 (time): empty", path=path, line=lines[bad[0]])
    back = np.flatnonzero(np.diff(times) < 0)
    if len(back):
        raise CaptureError(f"column 1 (time): {times[back[0] + 1]:g} comes after "
                           f"{times[back[0]]:g}; rows must be in time order", path=path,
                           line=lines[back[0] + 1])
    steps = np.diff(times)
    steps = steps[steps > 0]
    if settings["fps_given"] or not len(steps):
        fps = _fps(settings, path)
    else:
        fps = float(np.round(1.0 / np.median(steps), 6))
        if not 0.1 <= fps <= 10000:  # steps of 1e-300 s would make it 1e300
            raise CaptureError(f"column 1 (time): steps of {np.median(steps):g} s make "
                               f"{fps:g} frames per second, outside 0.1 to 10000; give the "
                               "rate as # fps=...", path=path, line=lines[0])
    numbers = np.round((times - times[0]) * fps)
    beyond = np.flatnonzero(numbers > MAX_FRAME_NUMBER)
    if len(beyond):
        raise CaptureError(f"column 1 (time): {times[beyond[0]]:g} s is frame "
                           f"{numbers[beyond[0]]:g}, beyond {MAX_FRAME_NUMBER}", path=path,
                           line=lines[beyond[0]])
    return fps, numbers.astype(np.int64)


def write_points_csv(take: PointTake, out, *, start: int | None = None,
                     stop: int | None = None) -> None:
    """Write frames ``[start, stop)`` of a point take in this layout, coordinates as stored.

    Each frame in which some point was seen is one row, numbered with the file's frame
    numbers (``frame``); frames with nothing seen have no row, as in a tracker's own files.
    Numbers are written in the shortest form that reads back to the same float. Point
    names are quoted as CSV needs (a comma, a quote) and protected from spreadsheets
    (``spreadsheet_safe``); the reader reads them back as they were.
    """
    start, stop = frame_range(take.n_frames, start, stop)
    xyz = take.channels[start:stop]
    names = io.StringIO()
    csv.writer(names, lineterminator="").writerow(
        ["frame"] + [spreadsheet_safe(f"{p}_{a}".replace("\r", " ").replace("\n", " "))
                     for p in take.point_names for a in "xyz"])
    unit = take.unit if take.unit.replace(".", "").isalnum() else "unknown"
    head = [f"# fps={take.fps:g} unit={unit} up={take.up}", names.getvalue()]
    rows = []
    for k in np.flatnonzero(~np.isnan(xyz).all(axis=1)):
        cells = ["" if np.isnan(v) else repr(float(v)) for v in xyz[k]]
        rows.append(",".join([str(take.first_number + start + int(k)), *cells]))
    text = "\n".join(head + rows) + "\n"
    if hasattr(out, "write"):
        out.write(text if isinstance(out, io.TextIOBase) else text.encode())
    else:
        Path(out).write_text(text)
