"""Text tables of point coordinates (Qualisys TSV, joint-position CSV): cells to numbers with
the line and column of any bad one, and rows placed on their frame clock.

An empty cell is a point not seen (NaN). Rows whose frame numbers skip are placed at their
number: frame ``k`` of the take is the file's frame ``first + k``, and a number without a
row is a frame in which nothing was seen. A number given twice keeps its first row (a
tracker that wrote a frame twice has nothing more to say about it).
"""

from __future__ import annotations

import math

import numpy as np

from motionlib.errors import CaptureError, shorten
from motionlib.io.numbers import read_rows


def data_lines(data: bytes, offset: int) -> list[tuple[int, int]]:
    """(start byte, 0-based line) of each non-blank line from ``offset`` on, in order."""
    out = []
    line = data.count(b"\n", 0, offset)
    pos = offset
    n = len(data)
    while pos < n:
        end = data.find(b"\n", pos)
        end = n if end < 0 else end
        if data[pos:end].strip():
            out.append((pos, line))
        pos, line = end + 1, line + 1
    return out


def parse_cells(data: bytes, offset: int, n_columns: int, delimiter: str, path,
                columns: list[str]) -> tuple[np.ndarray, list[int]]:
    """The rows of ``data[offset:]`` as numbers.

    Returns
    -------
    values : (n_rows, n_columns) float64, NaN for an empty cell.
    lines : 1-based file line of each row.

    Raises
    ------
    CaptureError
        At ``path:line``, naming the column of a cell that is not a finite number, or a row
        with another number of cells.
    """
    starts = data_lines(data, offset)
    text = data[offset:]
    fast = read_rows(text.replace(b",", b" ") if delimiter == "," else text, 0, len(starts),
                     n_columns)
    if fast is not None:
        return fast, [line + 1 for _, line in starts]
    values = np.empty((len(starts), n_columns))
    for row, (pos, line) in enumerate(starts):
        end = data.find(b"\n", pos)
        cells = data[pos: len(data) if end < 0 else end].decode("utf-8", "replace")
        cells = cells.rstrip("\r").split(delimiter)
        if delimiter == "\t" and len(cells) == n_columns + 1 and not cells[-1].strip():
            cells.pop()  # a trailing tab, as Qualisys writes one after the column names
        if len(cells) != n_columns:
            raise CaptureError(f"expected {n_columns} cells, found {len(cells)}", path=path,
                               line=line + 1)
        try:
            values[row] = [float(c) if c.strip() else math.nan for c in cells]
        except ValueError:
            values[row] = math.nan
        if not np.isfinite(values[row]).all():  # a gap, or a bad cell to name
            values[row] = [_cell(c, columns[k], k, path, line + 1) for k, c in enumerate(cells)]
    return values, [line + 1 for _, line in starts]


def _cell(cell: str, column: str, k: int, path, line: int) -> float:
    cell = cell.strip()
    if not cell or cell.lower() == "nan":
        return math.nan
    try:
        value = float(cell)
    except ValueError:
        raise CaptureError(f"column {k + 1} ({column}): {shorten(cell)} is not a number",
                           path=path, line=line) from None
    if not math.isfinite(value):
        raise CaptureError(f"column {k + 1} ({column}): {shorten(cell)} is not a finite number",
                           path=path, line=line)
    return value


# Frame numbers are kept as the file gives them and written back (C3D stores the first one
# as an unsigned 32-bit word); 1e19 would overflow every integer the service holds it in.
MAX_FRAME_NUMBER = 2**31 - 1


def frame_numbers(values: np.ndarray, lines: list[int], column: str, path) -> np.ndarray:
    """The first column as whole frame numbers from 0 to MAX_FRAME_NUMBER, rising or
    repeating, or a CaptureError at the line of the first that is missing, fractional, out
    of that range or going back."""
    numbers = values[:, 0]
    bad = np.flatnonzero(np.isnan(numbers) | (numbers != np.round(numbers)))
    if len(bad):
        raise CaptureError(f"column 1 ({column}): {numbers[bad[0]]:g} is not a whole frame "
                           "number", path=path, line=lines[bad[0]])
    bad = np.flatnonzero((numbers < 0) | (numbers > MAX_FRAME_NUMBER))
    if len(bad):
        raise CaptureError(f"column 1 ({column}): frame {numbers[bad[0]]:g} is outside 0 to "
                           f"{MAX_FRAME_NUMBER}", path=path, line=lines[bad[0]])
    back = np.flatnonzero(np.diff(numbers) < 0)
    if len(back):
        k = back[0] + 1
        raise CaptureError(f"column 1 ({column}): frame {int(numbers[k])} comes after frame "
                           f"{int(numbers[k - 1])}; rows must be in frame order", path=path,
                           line=lines[k])
    return numbers.astype(np.int64)


def check_coordinates(values: np.ndarray, first: int, lines: list[int], columns: list[str],
                      max_length: float, path) -> None:
    """Refuse a coordinate (columns ``first`` on of ``values``) beyond ``max_length`` in
    absolute value, naming its line, column and value.

    Such a value is finite as read (float64) but not as stored (float32 positions), and
    every later distance, speed or export of the take would turn it into infinities.
    """
    with np.errstate(invalid="ignore"):
        beyond = np.abs(values[:, first:]) > max_length
    rows = np.flatnonzero(beyond.any(axis=1))
    if len(rows):
        row = rows[0]
        k = first + int(np.flatnonzero(beyond[row])[0])
        raise CaptureError(f"column {k + 1} ({shorten(columns[k])}): {values[row, k]:g} is "
                           f"beyond the largest coordinate a take may hold (±{max_length:g})",
                           path=path, line=lines[row])


def on_clock(numbers: np.ndarray, rows: np.ndarray, max_frames: int, path) -> np.ndarray:
    """Rows ``(n_rows, ...)`` placed at frames ``numbers - numbers[0]`` of a take of
    ``numbers[-1] - numbers[0] + 1`` frames; frames without a row are NaN. A span of more
    than ``max_frames`` (the limits for a file of this size) is refused before allocating."""
    if len(numbers) == 0:
        return rows[:0]
    n_frames = int(numbers[-1] - numbers[0] + 1)
    if n_frames > max_frames:
        raise CaptureError(f"frame numbers {numbers[0]} to {numbers[-1]} span {n_frames} "
                           f"frames, more than the {max_frames} a file of this size may hold",
                           path=path)
    keep = np.ones(len(numbers), dtype=bool)
    keep[1:] = np.diff(numbers) > 0
    if keep.all() and n_frames == len(numbers):
        return rows
    out = np.full((n_frames, *rows.shape[1:]), np.nan)
    out[numbers[keep] - numbers[0]] = rows[keep]
    return out
