"""The segmentation benchmark: every method, default parameters, every labelled take.

Rows are the registered segmenters plus two peers from the change-point literature,
run on the same heading-invariant pose stream the default detector uses (10 joints in
the body frame plus root height; ``segmenters.default.pose_features``):

- ``ruptures_kernel``: ruptures ``KernelCPD`` with the RBF kernel (median-heuristic
  bandwidth), on the pose averaged to 10 Hz, minimum segment 2 s, one fixed penalty
  (``RUPTURES_PENALTY``) for every take.
- ``clasp``: claspy ``BinaryClaSPSegmentation`` with its own defaults (segment count
  learned), on the pose averaged to 30 Hz.

Both are imported only here, and only when the bench runs.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from motionlib import benchdata, metrics
from motionlib.segmenters import list_segmenters
from motionlib.segmenters.base import take_positions
from motionlib.segmenters.default import block_mean, pose_features

RUPTURES_PENALTY = 3.0

COLUMNS = (
    ("P@.5s", "precision@0.5s"), ("R@.5s", "recall@0.5s"), ("F1@.5s", "f1@0.5s"),
    ("P@1s", "precision@1s"), ("R@1s", "recall@1s"), ("F1@1s", "f1@1s"),
    ("edits/cut", "edits_per_cut"), ("med err s", "median_error_s"), ("time s", "time_s"),
    ("cuts", "n_cuts"),
)


def _peer_pose(take, rate_hz: float) -> tuple[np.ndarray, int, int]:
    positions, joints, first = take_positions(take)
    step = max(1, int(round(take.fps / rate_hz)))
    x = pose_features(positions, joints, fps=take.fps, velocity_s=0.0)
    return block_mean(x, step), step, first


def ruptures_kernel(take) -> np.ndarray:
    """Cuts from ruptures' kernel change-point detection (RBF, fixed penalty)."""
    import ruptures

    x, step, first = _peer_pose(take, 10.0)
    min_size = max(2, int(round(2.0 * take.fps / step)))
    ends = ruptures.KernelCPD(kernel="rbf", min_size=min_size).fit(x).predict(
        pen=RUPTURES_PENALTY
    )
    return np.asarray(ends[:-1], dtype=np.int64) * step + first


def clasp(take) -> np.ndarray:
    """Cuts from ClaSP (claspy defaults, number of segments learned)."""
    import warnings

    from claspy.segmentation import BinaryClaSPSegmentation

    x, step, first = _peer_pose(take, 30.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        found = BinaryClaSPSegmentation(n_jobs=1).fit_predict(x)
    return np.asarray(found, dtype=np.int64).reshape(-1) * step + first


def methods() -> dict[str, Callable]:
    """Row name -> function(take) -> cut frames, registered segmenters first."""
    rows: dict[str, Callable] = {
        cls.name: (lambda take, cls=cls: cls().fit_predict(take).cuts)
        for cls in list_segmenters()
    }
    rows["ruptures_kernel"] = ruptures_kernel
    rows["clasp"] = clasp
    return rows


def run(root: Path | None = None, only: list[str] | None = None) -> dict[str, dict]:
    """Evaluate every method on every labelled take.

    Returns
    -------
    take name -> method name -> metrics row (``metrics.evaluate`` plus time and count).
    """
    rows = {k: v for k, v in methods().items() if not only or k in only}
    results: dict[str, dict] = {}
    for labelled in benchdata.labelled_takes(root):
        take = labelled.read()
        results[labelled.name] = {}
        for name, detect in rows.items():
            start = time.perf_counter()
            cuts = detect(take)
            row = metrics.evaluate(cuts, labelled.truth, fps=take.fps)
            row["time_s"] = time.perf_counter() - start
            row["n_cuts"] = len(cuts)
            results[labelled.name][name] = row
    return results


def mean_rows(results: dict[str, dict]) -> dict[str, dict]:
    """Per method, the mean of each column over the takes (NaN errors skipped)."""
    names = next(iter(results.values())).keys() if results else []
    out = {}
    for name in names:
        per_take = [results[t][name] for t in results]
        out[name] = {
            key: _nanmean([row[key] for row in per_take]) for key in per_take[0]
        }
    return out


def _nanmean(values: list[float]) -> float:
    finite = [v for v in values if not math.isnan(v)]
    return sum(finite) / len(finite) if finite else float("nan")


def format_table(title: str, rows: dict[str, dict]) -> str:
    """A fixed-width text table, one row per method."""
    width = max([len(name) for name in rows] + [6])
    head = f"{'method':<{width}} " + " ".join(f"{label:>9}" for label, _ in COLUMNS)
    lines = [title, head, "-" * len(head)]
    for name, row in rows.items():
        cells = []
        for _, key in COLUMNS:
            value = row[key]
            cells.append(f"{value:>9.1f}" if key == "n_cuts" else f"{value:>9.3f}")
        lines.append(f"{name:<{width}} " + " ".join(cells))
    return "\n".join(lines)


def main(root: Path | None = None, only: list[str] | None = None, out=None) -> int:
    """Print a table per take and the mean table; 0 on success, 2 without data."""
    out = out or sys.stdout
    folder = Path(root) if root else benchdata.data_dir()
    if not folder.is_dir():
        print(f"error: benchmark data folder not found: {folder}", file=sys.stderr)
        return 2
    results = run(folder, only)
    for take, rows in results.items():
        truth = len(next(t for t in benchdata.labelled_takes(folder) if t.name == take).truth)
        print(format_table(f"\n{take} ({truth} true cuts)", rows), file=out)
    print(format_table(f"\nmean over {len(results)} takes", mean_rows(results)), file=out)
    if not only or "joint_distance_pca" in only:
        print("\n" + patent_comparison(folder), file=out)
    if not only or "default" in only:
        print(f"\ndefault on a 5-minute 120 fps synthetic take: {long_take_seconds():.2f} s",
              file=out)
    return 0


# CN102867300A's published run on CMU 13_30 (1-based AMC frames, first and last frame
# included as the patent lists them).
PATENT_13_30 = {
    "initial": [1, 196, 800, 1384, 1966, 2425, 2465],
    "final": [1, 208, 803, 1364, 1949, 2384, 2465],
}


def patent_comparison(root: Path) -> str:
    """joint_distance_pca's initial and final cuts on 13_30 beside the published ones."""
    from motionlib.segmenters import get_segmenter

    take = next(t for t in benchdata.labelled_takes(root) if t.name == "13_30").read()
    seg = get_segmenter("joint_distance_pca")()
    final = seg.fit_predict(take).cuts
    ours = {
        "initial": (seg.initial_cuts_ + 1).tolist(),
        "final": [1, *(final + 1).tolist(), take.n_frames],
    }
    lines = ["joint_distance_pca on 13_30 (AMC, 1-based frames) vs the patent's published run"]
    for stage in ("initial", "final"):
        lines.append(f"  {stage + ' published:':<19}{PATENT_13_30[stage]}")
        lines.append(f"  {stage + ' ours:':<19}{ours[stage]}")
        if len(ours[stage]) == len(PATENT_13_30[stage]):
            diff = np.abs(np.subtract(ours[stage], PATENT_13_30[stage]))
            lines.append(f"  {'max difference:':<19}{int(diff.max())} frames")
    return "\n".join(lines)


def long_take_seconds(minutes: float = 5.0) -> float:
    """Wall time of the default segmenter on a synthetic take of ``minutes`` at 120 fps."""
    from motionlib import synth
    from motionlib.segmenters import get_segmenter

    take, _ = synth.generate(seed=0, fps=120.0, duration=60.0 * minutes)
    start = time.perf_counter()
    get_segmenter("default")().fit_predict(take)
    return time.perf_counter() - start


def add_bench(subparsers) -> None:
    """Register ``python -m motionlib bench`` (see ``motionlib.cli``)."""
    p = subparsers.add_parser(
        "bench", help="benchmark the segmenters on the labelled CMU takes",
        description="Every segmenter (default parameters) and two change-point peers on "
                    "every labelled take: a table per take and the mean.",
    )
    p.add_argument("--data", help="benchmark data folder (default: ../shared/data)")
    p.add_argument("--method", action="append", help="only this row (repeatable)")
    p.set_defaults(handler=lambda args: main(args.data, args.method))
