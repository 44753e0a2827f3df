"""The examples CSV: take files and their human cuts, for ``fit_cut_model``."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from motionlib.errors import MotionlibError


class ExampleError(MotionlibError):
    """An example take or its cuts cannot be learnt from; the message names it."""


EXAMPLE_COLUMNS = ("file", "asf", "cuts")


def read_examples(path) -> list[tuple[object, np.ndarray]]:
    """Example takes and their human cuts from a CSV with the header ``file,asf,cuts``.

    ``file`` is a BVH or AMC path (relative paths from the CSV's folder), ``asf`` the ASF of
    an AMC (empty for BVH), ``cuts`` 0-based take frames separated by spaces.

    Raises
    ------
    ExampleError naming the CSV, the line and the value for a malformed row, an unreadable
    take or a cut outside its take.
    """
    import motionlib

    path = Path(path)
    try:
        # utf-8-sig: a spreadsheet's "CSV UTF-8" starts with a byte-order mark.
        with open(path, newline="", encoding="utf-8-sig") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError) as exc:
        raise ExampleError(f"{path}: cannot read examples: {exc}") from None
    header = [c.strip() for c in rows[0]] if rows else []
    if tuple(header) != EXAMPLE_COLUMNS:
        raise ExampleError(f"{path}:1: expected the header {','.join(EXAMPLE_COLUMNS)}, "
                           f"got {','.join(header) or 'nothing'!r}")
    examples = []
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != 3:
            raise ExampleError(f"{path}:{line}: expected 3 fields (file,asf,cuts), "
                               f"got {len(row)}: {','.join(row)!r}")
        file, asf, text = (cell.strip() for cell in row)
        cuts = _parse_cuts(path, line, text)
        if not file:
            raise ExampleError(f"{path}:{line}: file is empty")
        take_path = path.parent / file
        asf_path = path.parent / asf if asf else None
        try:
            take = motionlib.read(take_path, asf=asf_path)
        except (ValueError, OSError) as exc:
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise ExampleError(f"{path}:{line}: cannot read {file}: {first}") from None
        for cut in cuts:
            if not 0 < cut < take.n_frames:
                raise ExampleError(f"{path}:{line}: cut {cut} is outside {file} "
                                   f"({take.n_frames} frames; 1 to {take.n_frames - 1} can "
                                   f"start a segment)")
        examples.append((take, np.asarray(cuts, dtype=np.int64)))
    if not examples:
        raise ExampleError(f"{path}: no example takes")
    return examples


def _parse_cuts(path: Path, line: int, text: str) -> list[int]:
    cuts = []
    for word in text.split():
        try:
            cuts.append(int(word))
        except ValueError:
            raise ExampleError(f"{path}:{line}: cut {word!r} is not a whole frame "
                               f"number") from None
    return cuts
