"""Segmentation quality on the labelled point takes: every registered segmenter and ruptures,
per take and mean, on each point set at its tolerance.

Sets (``../shared/data/points``, README there):

- ``hdm05`` (Vicon C3D, Plug-in Gait, 120 Hz), tolerance 1 s. Labels are sparse intervals
  (tpose / neutral / others) with unlabelled motion between them, so every start and end of
  an interval inside the take is a true cut.
- ``utkinect`` (Kinect v1 joints, 30 Hz clock, irregular rows), tolerance 1 s. Ten actions
  per take with an unlabelled gap between two: the true cut between consecutive actions is
  the window [end of one, start of the next] (``motionlib.metrics`` windows).
- ``vmci`` (Qualisys TSV, 13 markers of arm, hand, back and box: no known marker set, so
  bare points), tolerance 0.25 s. Segments at their finest level (a segment's ``_part``
  pieces where it has them): the true cut between consecutive segments is the window
  [end of one, start of the next].

Every method runs with its shipped defaults: nothing here is tuned, on any subject. A method
that cannot run on a set (the methods that need body parts on bare points) is reported with
its reason. ``ruptures``: ``KernelCPD`` (RBF kernel, penalty 3, as the rotation benchmark's
``ruptures_kernel``) on the body-frame positions of the body parts (bare points: their
coordinates), averaged into 10 Hz blocks; its minimum segment is twice the set's
tolerance (shorter segments could not be told apart at that tolerance).

Columns: precision, recall and F1 within the tolerance (one-to-one matching,
``motionlib.metrics.boundary_scores``), review edits per true cut (``edit_cost`` with the
tolerance as its match distance), candidate cuts, true cuts and seconds.

    .venv/bin/python -m benchmarks points-quality -- [--data ../shared/data] [--sets hdm05,vmci]
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import motionlib
from benchmarks.harness import data_dir
from motionlib import features, markersets, metrics
from motionlib.errors import MotionlibError
from motionlib.points import filled
from motionlib.segmenters import list_segmenters

DEFAULT_DATA = data_dir()
RUPTURES_PENALTY = 3.0
RUPTURES_RATE_HZ = 10.0


@dataclass
class LabelledTake:
    """A point take file and its true cuts, ``(n, 3)`` windows of 0-based take frames."""

    name: str
    subject: str
    path: Path
    truth: np.ndarray | None = None
    take: object = None

    def read(self):
        if self.take is None:
            self.take = motionlib.read(self.path)
        return self.take


@dataclass
class PointSet:
    name: str
    tolerance_s: float
    takes: list[LabelledTake]


def between(segments: list[tuple[int, int]], n_frames: int) -> np.ndarray:
    """Windows [end of one, start of the next] between consecutive segments (take frames,
    ``(start, end)`` inclusive, sorted by start); an overlap gives [start, end] of it."""
    rows = []
    for (_, end), (start, _) in zip(segments, segments[1:], strict=False):
        lo, hi = sorted((end, start))
        if 0 < hi and lo < n_frames - 1:
            rows.append((lo, (lo + hi) // 2, hi))
    return metrics.as_windows(np.array(rows, dtype=np.int64).reshape(-1, 3))


def hdm05(data: Path) -> PointSet:
    folder = data / "points" / "hdm05"
    intervals: dict[str, list[tuple[int, int]]] = {}
    with open(folder / "labels.csv", newline="") as handle:
        for row in csv.DictReader(handle):
            intervals.setdefault(row["take"], []).append((int(row["start_frame"]),
                                                          int(row["end_frame"])))
    takes = []
    for name, spans in sorted(intervals.items()):
        item = LabelledTake(name, name.split("_")[1], folder / f"{name}.c3d")
        take = item.read()
        cuts = set()
        for start, end in spans:  # 1-based inclusive file frames
            for cut in (start - take.first_number, end + 1 - take.first_number):
                if 0 < cut < take.n_frames:
                    cuts.add(cut)
        item.truth = metrics.as_windows(np.array(sorted(cuts), dtype=np.int64))
        takes.append(item)
    return PointSet("hdm05", 1.0, takes)


def utkinect(data: Path) -> PointSet:
    folder = data / "points" / "utkinect"
    actions: dict[str, list[tuple[int, int]]] = {}
    with open(folder / "labels.csv", newline="") as handle:
        for row in csv.DictReader(handle):
            actions.setdefault(row["take"], []).append((int(row["start_frame_id"]),
                                                        int(row["end_frame_id"])))
    takes = []
    for name, spans in sorted(actions.items()):
        item = LabelledTake(name, name.split("_")[0], folder / f"{name}.csv")
        take = item.read()
        shifted = sorted((s - take.first_number, e - take.first_number) for s, e in spans)
        item.truth = between(shifted, take.n_frames)
        takes.append(item)
    return PointSet("utkinect", 1.0, takes)


def finest(segments: list[dict]) -> list[tuple[int, int]]:
    """Each top-level segment replaced by its ``_part`` pieces where it has them."""
    parts = [(s["start index"], s["end index"]) for s in segments
             if s["label"].endswith("_part")]
    out = list(parts)
    for s in segments:
        if s["label"].endswith("_part"):
            continue
        start, end = s["start index"], s["end index"]
        inside = [p for p in parts if p[0] >= start - 1 and p[1] <= end + 1]
        if not inside:
            out.append((start, end))
    return sorted(out)


def vmci(data: Path) -> PointSet:
    folder = data / "points" / "vmci"
    takes = []
    for path in sorted(folder.glob("subject*_run*.tsv"), key=lambda p: (len(p.stem), p.stem)):
        item = LabelledTake(path.stem, path.stem.split("_")[0], path)
        take = item.read()
        with open(folder / f"{path.stem}_manually_segmented.json") as handle:
            segments = finest(json.load(handle))
        shifted = [(s - take.first_number, e - take.first_number) for s, e in segments]
        item.truth = between(shifted, take.n_frames)
        takes.append(item)
    return PointSet("vmci", 0.25, takes)


SETS: dict[str, Callable[[Path], PointSet]] = {"hdm05": hdm05, "utkinect": utkinect,
                                               "vmci": vmci}


def pose_rows(take) -> np.ndarray:
    """Per-frame features for ruptures: body-frame positions of the body parts, or the
    coordinates of bare points; gaps closed."""
    if take.marker_set is None:
        points = filled(take.positions)
        seen = ~np.isnan(points[0, :, 0])
        return points[:, seen].reshape(take.n_frames, -1)
    positions, joints = markersets.body_joints(take)
    named = [j for part, j in joints.items() if part != "root"]
    return features.body_frame_positions(positions, joints, named).reshape(take.n_frames, -1)


def ruptures_cuts(take, tolerance_s: float) -> np.ndarray:
    import ruptures

    x = pose_rows(take)
    step = max(1, int(round(take.fps / RUPTURES_RATE_HZ)))
    n = len(x) // step
    blocks = x[: n * step].reshape(n, step, -1).mean(axis=1)
    min_size = max(2, int(round(2 * tolerance_s * RUPTURES_RATE_HZ)))
    ends = ruptures.KernelCPD(kernel="rbf", min_size=min_size).fit(blocks).predict(
        pen=RUPTURES_PENALTY)
    return np.asarray(ends[:-1], dtype=np.int64) * step


def methods(tolerance_s: float) -> dict[str, Callable]:
    rows: dict[str, Callable] = {
        cls.name: (lambda take, cls=cls: cls().fit_predict(take).cuts)
        for cls in list_segmenters()
    }
    rows["ruptures"] = lambda take: ruptures_cuts(take, tolerance_s)
    return rows


def score(point_set: PointSet) -> dict[str, dict]:
    """Method -> {"rows": per-take dicts, "error": reason it cannot run, or None}."""
    out = {}
    for method, find in methods(point_set.tolerance_s).items():
        rows, error = [], None
        for item in point_set.takes:
            take = item.read()
            start = time.perf_counter()
            try:
                cuts = np.asarray(find(take))
            except MotionlibError as exc:
                error = str(exc).split(": ", 1)[-1]
                break
            seconds = time.perf_counter() - start
            s = metrics.boundary_scores(cuts, item.truth, fps=take.fps,
                                        tolerance_s=point_set.tolerance_s)
            edits = metrics.edit_cost(cuts, item.truth, fps=take.fps,
                                      match_s=point_set.tolerance_s)
            rows.append({"take": item.name, "subject": item.subject, "P": s["precision"],
                         "R": s["recall"], "F1": s["f1"], "edits": edits["edits_per_cut"],
                         "cuts": len(cuts), "true": len(item.truth), "s": seconds})
        out[method] = {"rows": rows, "error": error}
    return out


COLUMNS = (("P", "{:.2f}"), ("R", "{:.2f}"), ("F1", "{:.2f}"), ("edits", "{:.2f}"),
           ("cuts", "{:.0f}"), ("true", "{:.0f}"), ("s", "{:.2f}"))


def print_set(point_set: PointSet, scores: dict[str, dict]) -> None:
    first = point_set.takes[0].read()
    n = len(point_set.takes)
    print(f"\n## {point_set.name}: {n} take{'' if n == 1 else 's'}, {first.format.upper()}, "
          f"{first.fps:g} Hz, marker set {first.marker_set or 'none (bare points)'}, "
          f"tolerance {point_set.tolerance_s:g} s")
    header = f"{'method':<20}{'take':<22}" + "".join(f"{c:>8}" for c, _ in COLUMNS)
    print(header)
    for method, result in scores.items():
        if result["error"]:
            print(f"{method:<20}{'cannot run':<22}{result['error'][:200]}")
            continue
        for row in result["rows"]:
            print(f"{method:<20}{row['take']:<22}" + "".join(
                f"{fmt.format(row[c]):>8}" for c, fmt in COLUMNS))
        mean = {c: np.mean([r[c] for r in result["rows"]]) for c, _ in COLUMNS}
        print(f"{method:<20}{'mean':<22}" + "".join(
            f"{fmt.format(mean[c]):>8}" for c, fmt in COLUMNS))


def print_summary(all_scores: dict[str, tuple[PointSet, dict]]) -> None:
    print("\n## mean F1 per set (P / R / F1)")
    names = list(next(iter(all_scores.values()))[1])
    print(f"{'method':<20}" + "".join(f"{s:>22}" for s in all_scores))
    for method in names:
        cells = []
        for _, scores in all_scores.values():
            result = scores[method]
            if result["error"]:
                cells.append("cannot run")
            else:
                m = [np.mean([r[c] for r in result["rows"]]) for c in ("P", "R", "F1")]
                cells.append(f"{m[0]:.2f} / {m[1]:.2f} / {m[2]:.2f}")
        print(f"{method:<20}" + "".join(f"{c:>22}" for c in cells))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    parser.add_argument("--sets", default=",".join(SETS))
    args = parser.parse_args(argv)
    if not (args.data / "points").is_dir():
        sys.exit(f"{args.data / 'points'} not found (needs ../shared/data/points)")
    all_scores = {}
    for name in args.sets.split(","):
        point_set = SETS[name](args.data)
        all_scores[name] = (point_set, score(point_set))
        print_set(point_set, all_scores[name][1])
    print_summary(all_scores)

