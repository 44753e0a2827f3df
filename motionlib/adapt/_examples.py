"""Example takes and their human cuts, as the learner is given them: a (take, cuts) pair
or an :class:`Example` described before it is read, its cuts checked against the take
(``checked_cuts``); and the examples CSV of the command line (``read_examples``)."""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from motionlib.errors import MotionlibError


class ExampleError(MotionlibError):
    """An example take or its cuts cannot be learnt from; the message names it."""


EXAMPLE_COLUMNS = ("file", "asf", "cuts")


@dataclass(frozen=True)
class Example:
    """An example take described before it is read, so that a stored study can stand in
    for reading and analysing it (``fit_cut_model``'s ``studies``).

    name : how an error names the take; cuts : its human cuts (0-based take frames);
    fps, n_frames : the take's frame rate and length; read : returns the take;
    key : identifies the take's content (e.g. its file's checksum), or None to never
    store its study.
    weight : how much the take may count, in (0, 1]: the learner's own weighting of takes
        that disagree with the others multiplies it (the service caps one annotator's
        share of the examples this way).
    """

    name: str
    cuts: Sequence[int]
    fps: float
    n_frames: int
    read: Callable[[], object]
    key: str | None = None
    weight: float = 1.0


def as_example(item) -> Example:
    """``item`` as an :class:`Example`: itself, or a (take, cuts) pair whose take is at hand."""
    if isinstance(item, Example):
        return item
    take, cuts = item
    return Example(name=_where(take), cuts=cuts, fps=float(take.fps), n_frames=take.n_frames,
                   read=lambda: take)


def _where(take) -> str:
    return os.path.basename(take.path) if getattr(take, "path", None) else take.name


def checked_cuts(example: Example) -> np.ndarray:
    """The example's cuts as sorted unique int frames inside its take; ExampleError naming
    a bad one."""
    out = []
    for value in example.cuts:
        number = float(value)
        if not math.isfinite(number) or number != int(number):
            raise ExampleError(f"{example.name}: cut {value!r} is not a whole frame")
        if not 0 < int(number) < example.n_frames:
            raise ExampleError(f"{example.name}: cut {int(number)} is outside the take "
                               f"(frames 1 to {example.n_frames - 1} can start a segment)")
        out.append(int(number))
    return np.unique(np.asarray(out, dtype=np.int64))


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
