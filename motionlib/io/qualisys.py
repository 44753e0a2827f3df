"""Qualisys Track Manager TSV exports of 3D markers.

Layout: header lines ``KEY<tab>value...`` (``NO_OF_FRAMES``, ``FREQUENCY``,
``NO_OF_MARKERS``, ``MARKER_NAMES``, ...), then either a column line
``Frame<tab>Time<tab><marker> X<tab><marker> Y<tab><marker> Z...`` and rows of those
columns, or (older exports) rows of X, Y, Z per marker in ``MARKER_NAMES`` order, frames
numbered from 1. Positions are in millimetres, Z up (Qualisys' global frame). An empty cell
is a marker not seen, and so is a marker whose three coordinates are all exactly 0: some
exports write ``0.000`` there instead of leaving the cells empty, and a tracked marker at
the very origin of the lab to the micrometre is not a position a take holds. ``NO_OF_FRAMES`` is the recording's length, which an export of a
part of it does not have, so the rows decide the frames.
"""

from __future__ import annotations

import os
from collections import Counter
from pathlib import Path

import numpy as np

from motionlib.errors import CaptureError, shorten
from motionlib.io.pointtext import check_coordinates, frame_numbers, on_clock, parse_cells
from motionlib.io.text import read_lines_bytes
from motionlib.points import PointTake, make_point_take
from motionlib.take import (
    DEFAULT_LIMITS,
    Limits,
    check_point_names,
    check_points,
    check_size,
    max_frames_for,
)

MAX_HEADER_LINES = 100


def read_qualisys_tsv(path: str | os.PathLike, *,
                      limits: Limits = DEFAULT_LIMITS) -> PointTake:
    """Read a Qualisys TSV export.

    Returns
    -------
    PointTake
        ``format == "tsv"``; ``fps`` from ``FREQUENCY``; ``first_number`` the first row's
        ``Frame``; a frame number without a row is a frame with no marker seen.

    Raises
    ------
    CaptureError
        At ``file:line``, naming the header key or the column at fault.
    """
    path = os.fspath(path)
    data = read_lines_bytes(path)
    header, offset, line = _header(data, path)
    fps = _frequency(header, path)
    names = _marker_names(header, path, limits)
    columns, offset = _columns(data, offset, line, names, path)
    values, lines = parse_cells(data, offset, len(columns), "\t", path, columns)
    check_size(len(values), len(names), 3 * len(names), len(data), limits, path=path)
    framed = columns[0] == "Frame"
    check_coordinates(values, 2 if framed else 0, lines, columns, limits.max_length, path)
    numbers = (frame_numbers(values, lines, "Frame", path) if framed
               else np.arange(1, len(values) + 1))
    first = 2 if framed else 0
    coordinates = values[:, first:].reshape(len(values), len(names), 3)
    coordinates[(coordinates == 0).all(axis=-1)] = np.nan
    coordinates = on_clock(numbers, coordinates, max_frames_for(
        len(names), 3 * len(names), len(data), limits), path)
    return make_point_take(name=Path(path).stem, format="tsv", fps=fps,
                           coordinates=coordinates, names=names, unit="mm", up="z",
                           first_number=int(numbers[0]) if len(numbers) else 0, path=path)


def _header(data: bytes, path) -> tuple[dict[str, tuple[list[str], int]], int, int]:
    """Header keys -> (values, 1-based line), the byte and 0-based line after the header."""
    header: dict[str, tuple[list[str], int]] = {}
    pos, line = 0, 0
    while pos < len(data) and line < MAX_HEADER_LINES:
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end
        text = data[pos:end].decode("utf-8", "replace").rstrip("\r")
        key, *values = text.split("\t")
        if not key.strip() and not values:
            pos, line = end + 1, line + 1
            continue
        if key == "Frame" or not key.isupper() or not key.replace("_", "").isalnum():
            break
        header[key] = ([v.strip() for v in values], line + 1)
        pos, line = end + 1, line + 1
    if "MARKER_NAMES" not in header and "FREQUENCY" not in header:
        raise CaptureError("line 1: not a Qualisys TSV export (no FREQUENCY or MARKER_NAMES "
                           "header line)", path=path, line=1)
    return header, pos, line


def _frequency(header, path) -> float:
    if "FREQUENCY" not in header:
        raise CaptureError("header: no FREQUENCY line (the frame rate)", path=path)
    values, line = header["FREQUENCY"]
    try:
        fps = float(values[0])
    except (ValueError, IndexError):
        raise CaptureError(f"FREQUENCY: {shorten(values[0] if values else '')} is not a "
                           "number", path=path, line=line) from None
    if not 0.1 <= fps <= 10000:
        raise CaptureError(f"FREQUENCY: {fps:g} frames per second is outside 0.1 to 10000",
                           path=path, line=line)
    return fps


def _marker_names(header, path, limits: Limits) -> list[str]:
    """The markers as MARKER_NAMES names them: at most ``limits.max_joints``, each once.
    Linear in their number (a list's ``count`` per name made 60,000 names cost minutes)."""
    if "MARKER_NAMES" not in header:
        raise CaptureError("header: no MARKER_NAMES line", path=path)
    names, line = header["MARKER_NAMES"]
    names = [n for n in names if n]
    if not names:
        raise CaptureError("MARKER_NAMES: no marker named", path=path, line=line)
    check_points(len(names), limits, path=path, line=line, what="markers")
    check_point_names(names, limits, path=path, line=line, what="marker")
    if len(set(names)) != len(names):
        twice = next(n for n, count in Counter(names).items() if count > 1)
        raise CaptureError(f"MARKER_NAMES: {shorten(twice)} is named twice", path=path,
                           line=line)
    if "NO_OF_MARKERS" in header:
        count, count_line = header["NO_OF_MARKERS"]
        if count and count[0] != str(len(names)):
            raise CaptureError(f"NO_OF_MARKERS: {shorten(count[0])} markers, but MARKER_NAMES "
                               f"names {len(names)}", path=path, line=count_line)
    return names


def _columns(data: bytes, offset: int, line: int, names: list[str], path):
    """The column names and the byte where the rows start; the markers in column order."""
    end = data.find(b"\n", offset)
    end = len(data) if end < 0 else end
    cells = data[offset:end].decode("utf-8", "replace").rstrip("\r").split("\t")
    if cells[0] != "Frame":
        return [f"{n} {axis}" for n in names for axis in "XYZ"], offset
    if cells and not cells[-1].strip():
        cells.pop()
    expected = ["Frame", "Time"] + [f"{n} {axis}" for n in names for axis in "XYZ"]
    known = set(expected)
    if len(cells) != len(expected) or set(cells) != known:
        wrong = next((k for k, a in enumerate(cells[:len(expected)]) if a not in known),
                     min(len(cells), len(expected)))
        raise CaptureError(f"column {wrong + 1}: the column line does not match MARKER_NAMES "
                           f"(expected Frame, Time and X, Y, Z of {len(names)} markers, found "
                           f"{len(cells)} columns)", path=path, line=line + 1)
    order = [cells[2 + 3 * k][:-2] for k in range(len(names))]
    if any(cells[2 + 3 * k + i] != f"{order[k]} {axis}" for k in range(len(names))
           for i, axis in enumerate("XYZ")):
        raise CaptureError("the column line must give X, Y, Z of each marker in turn",
                           path=path, line=line + 1)
    names[:] = order
    return cells, end + 1
