"""The labelled real CMU takes used by the segmentation benchmark and tests.

The data lives in the ``shared/data`` folder beside the repository (see its README):
mocap6 labels for 13_29 and 13_30 (runs of 10 fps blocks, AMC frames 1-based), and the
Krüger et al. 2017 transition windows for subject 86. Every loader returns true cuts
as ``(n, 3)`` windows ``(lo, mid, hi)`` of 0-based *take* frames (``motionlib.metrics``).
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DEFAULT_DATA_DIR = Path(__file__).resolve().parents[1] / ".." / "shared" / "data"


class LabelError(ValueError):
    """A label file is malformed; the message names the file, line and value."""


def data_dir() -> Path:
    """The benchmark data folder (``$CUTROOM_BENCH_DATA`` overrides the default)."""
    return Path(os.environ.get("CUTROOM_BENCH_DATA", DEFAULT_DATA_DIR)).resolve()


@dataclass(frozen=True)
class LabelledTake:
    """One capture with human cuts: ``truth`` is ``(n, 3)`` windows in take frames."""

    name: str
    path: Path
    asf: Path | None
    truth: np.ndarray
    source: str

    def read(self):
        import motionlib

        return motionlib.read(self.path, asf=self.asf)


def _rows(path: Path, columns: tuple[str, ...]) -> list[tuple[int, dict[str, str]]]:
    """CSV rows with their line numbers; LabelError if a column is missing."""
    with open(path, newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        missing = [c for c in columns if c not in (reader.fieldnames or [])]
        if missing:
            raise LabelError(f"{path}: line 1: missing column {missing[0]!r}")
        return [(reader.line_num, row) for row in reader]


def _int(path: Path, line: int, row: dict[str, str], column: str) -> int:
    value = row.get(column)
    try:
        return int(value)
    except (TypeError, ValueError):
        raise LabelError(f"{path}: line {line}: {column} is not an integer: {value!r}") from None


def mocap6_truth(path: Path, *, frame_offset: int = 0) -> np.ndarray:
    """True cuts from a mocap6 ``segments/<seq>.csv``.

    Each segment after the first starts a new activity at AMC frame ``start_frame``
    (1-based), i.e. 0-based AMC frame ``start_frame - 1``; ``frame_offset`` converts to
    another take's frames (+1 for the cgspeed BVH, whose line 0 is an added T-pose).
    """
    path = Path(path)
    starts = [_int(path, n, r, "start_frame") for n, r in _rows(path, ("start_frame",))]
    if not starts:
        raise LabelError(f"{path}: no segments")
    if starts != sorted(starts):
        raise LabelError(f"{path}: start_frame values are not increasing: {starts}")
    cuts = np.asarray(starts[1:], dtype=np.int64) - 1 + frame_offset
    return np.repeat(cuts[:, None], 3, axis=1)


def kruger_truth(path: Path) -> np.ndarray:
    """True cuts from a subject-86 ``cmu86_kruger2017/86_XX.csv``.

    Segment k ends somewhere in AMC frames ``[end_lo, end_hi]`` (1-based, inclusive),
    best estimate ``end_mid``; the next segment starts one frame later, which is 0-based
    frame ``end`` itself. The last row only repeats the trial length and is no cut.
    """
    path = Path(path)
    cols = ("end_lo", "end_mid", "end_hi")
    rows = [[_int(path, n, r, c) for c in cols] for n, r in _rows(path, cols)]
    if not rows:
        raise LabelError(f"{path}: no segments")
    return np.sort(np.asarray(rows[:-1], dtype=np.int64).reshape(-1, 3), axis=1)


def labelled_takes(root: Path | None = None, *, bvh: bool = True) -> list[LabelledTake]:
    """The benchmark's labelled takes, in a fixed order.

    13_29 is read from the cgspeed BVH when ``bvh`` is true (label frames shifted by its
    T-pose line), else from the AMC; 13_30 and 86_01 from the AMC.
    """
    root = Path(root) if root is not None else data_dir()
    if not root.is_dir():
        raise FileNotFoundError(f"benchmark data folder not found: {root}")
    cmu, labels = root / "cmu", root / "labels"
    seg29 = labels / "mocap6" / "segments" / "13_29.csv"
    if bvh:
        take29 = LabelledTake(
            "13_29", cmu / "bvh" / "13_29.bvh", None, mocap6_truth(seg29, frame_offset=1),
            "mocap6",
        )
    else:
        take29 = LabelledTake(
            "13_29", cmu / "amc" / "13_29.amc", cmu / "asf" / "13.asf", mocap6_truth(seg29),
            "mocap6",
        )
    return [
        take29,
        LabelledTake(
            "13_30", cmu / "amc" / "13_30.amc", cmu / "asf" / "13.asf",
            mocap6_truth(labels / "mocap6" / "segments" / "13_30.csv"), "mocap6",
        ),
        LabelledTake(
            "86_01", cmu / "amc" / "86_01.amc", cmu / "asf" / "86.asf",
            kruger_truth(labels / "cmu86_kruger2017" / "86_01.csv"), "kruger2017",
        ),
    ]
