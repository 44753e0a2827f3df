"""The segmentation quality benchmark: every method, default parameters, every labelled take.

``python -m benchmarks quality``. Takes are found by ``data.discover`` (every
labelled take in the shared data layout; four-channel takes run only the methods that need
no skeleton). Rows are the registered segmenters plus two peers from the change-point
literature, run on the same heading-invariant pose stream the default detector uses
(``segmenters.default.take_features``):

- ``ruptures_kernel``: ruptures ``KernelCPD`` with the RBF kernel (median-heuristic
  bandwidth), on the pose averaged to 10 Hz, minimum segment 2 s, one fixed penalty
  (``RUPTURES_PENALTY``) for every take.
- ``clasp``: claspy ``BinaryClaSPSegmentation`` with its own defaults (segment count
  learned), on the pose averaged to 30 Hz.

Both are imported only here, and only when the bench runs.

With ``--loo`` the rows of ``LOO_ROWS`` are scored leave-one-take-out: settings and
penalties chosen, and the adapted model fitted, without the take scored (nor its other
views), so that no figure is in-sample. The checks of ``checks`` and ``unmatched``, and the
tables of how the settings were chosen (``tables``), follow the per-take tables.

Leave-one-take-out chooses on all the labelled material there is: ``--pool DIR`` adds the
labelled takes under DIR to what is chosen on and learnt from, without scoring them. By
default the pool is the shared data the shipped settings were chosen on
(``default_pool``) when the takes scored are elsewhere, so that a few new takes are scored
with settings chosen on everything else, as the shipped ones were. A take with no other
capture to choose on gets NaN in the /loo rows.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from benchmarks.quality import data, tuning
from benchmarks.quality.checks import (
    edge_activity_check,
    long_take_check,
    placement_bound_check,
    real_short_activity_check,
    short_activity_check,
    short_takes_check,
    tempo_check,
)
from benchmarks.quality.tables import (
    COLUMNS,
    format_table,
    mean_rows,
    out_of_sample_table,
    placement_summary,
)
from benchmarks.quality.tried import detector
from benchmarks.quality.unmatched import unmatched_choice_check, unmatched_guard_check
from motionlib import adapt, metrics, shared_data
from motionlib.errors import CaptureError
from motionlib.segmenters import list_segmenters
from motionlib.segmenters.default import take_features

RUPTURES_PENALTY = 3.0


def _peer_pose(take, rate_hz: float) -> tuple[np.ndarray, int, int]:
    x, first = take_features(take)
    step = max(1, int(round(take.fps / rate_hz)))
    n = len(x) // step  # the poses averaged over blocks of step frames
    return x[: n * step].reshape(n, step, -1).mean(axis=1), step, first


def ruptures_kernel(take, penalty: float = RUPTURES_PENALTY) -> np.ndarray:
    """Cuts from ruptures' kernel change-point detection (RBF, fixed penalty)."""
    import ruptures

    x, step, first = _peer_pose(take, 10.0)
    min_size = max(2, int(round(2.0 * take.fps / step)))
    ends = ruptures.KernelCPD(kernel="rbf", min_size=min_size).fit(x).predict(pen=penalty)
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


# Methods that need only a feature stream run on four-channel takes too; the others
# need a skeleton.
FEATURE_ONLY = {"default", "ruptures_kernel", "clasp"}


def methods() -> dict[str, Callable]:
    """Row name -> function(take) -> cut frames, registered segmenters first."""
    rows: dict[str, Callable] = {
        cls.name: (lambda take, cls=cls: cls().fit_predict(take).cuts)
        for cls in list_segmenters()
    }
    rows["ruptures_kernel"] = ruptures_kernel
    rows["clasp"] = clasp
    return rows


def title(labelled) -> str:
    """A take's row label: its name, marked when only four channels are known."""
    return labelled.name + (" (4 channels)" if labelled.kind == "channels" else "")


def _timed_row(detect, take, truth) -> dict:
    start = time.perf_counter()
    cuts = detect(take)
    row = metrics.evaluate(cuts, truth, fps=take.fps)
    row["time_s"] = time.perf_counter() - start
    row["n_cuts"] = len(cuts)
    return row


def run(root: Path | None = None, only: list[str] | None = None, *, loo: bool = False,
        log=None, selection_out: list | None = None, pool=(),
        cache_out: list | None = None) -> dict[str, dict]:
    """Evaluate every method on every labelled take under ``root``.

    With ``loo``, four more rows are scored leave-one-take-out (see ``LOO_ROWS``), chosen
    on the other takes under ``root`` and the labelled takes under the ``pool`` folders.
    ``cache_out`` receives each take scored, read (``tuning.TakeCache``), for the checks
    that follow the tables.

    Returns
    -------
    take title -> method name -> metrics row (``metrics.evaluate`` plus time and count).
    """
    rows = {k: v for k, v in methods().items() if not only or k in only}
    takes, skipped = data.discover(root)
    for line in skipped:
        print(line, file=log or sys.stderr)
    cache = read_takes(takes, log)
    if cache_out is not None:
        cache_out.extend(cache)
    results: dict[str, dict] = {}
    for c in cache:
        results[title(c.labelled)] = {
            name: _timed_row(detect, c.take, c.labelled.truth)
            for name, detect in rows.items()
            if c.labelled.kind == "skeleton" or name in FEATURE_ONLY
        }
    if loo:
        cache += pool_cache(pool, [c.labelled for c in cache], log)
        tried = tuning.select(cache, tuning.grid_choices(tuning.tried_grid()))
        if selection_out is not None:
            selection_out.append(tried)
        scored = [c for c in cache if not c.pool]
        for key, per_take in loo_rows(cache, tried).items():
            for c, row in zip(scored, per_take, strict=True):
                results[title(c.labelled)][key] = row
    return results


def pool_cache(folders, scored, log=None) -> list[tuning.TakeCache]:
    """The labelled takes under ``folders``, read, as ``pool`` takes: those with the name
    and kind of a take in ``scored`` (or already pooled) left out."""
    seen = {(t.name, t.kind) for t in scored}
    out = []
    for folder in folders:
        takes, skipped = data.discover(folder)
        for line in skipped:
            print(f"pool {folder}: {line}", file=log or sys.stderr)
        fresh = [t for t in takes if (t.name, t.kind) not in seen]
        seen.update((t.name, t.kind) for t in fresh)
        out += read_takes(fresh, log, pool=True, prefix=f"pool {folder}: ")
    return out


def read_takes(takes, log=None, *, pool: bool = False, prefix: str = "") -> list:
    """``takes`` read (``tuning.TakeCache``); one whose motion cannot be read or whose
    labels do not fit it (``data.LabelledTake.read``) is skipped with a line saying
    so."""
    out = []
    for t in takes:
        try:
            out.append(tuning.TakeCache(t, t.read(), pool=pool))
        except (data.LabelError, CaptureError) as exc:
            print(f"{prefix}skipped {t.name} ({t.path.name}): {exc}", file=log or sys.stderr)
    return out


def default_pool(folder: Path) -> list[Path]:
    """The shared data the shipped settings were chosen on: ``shared_data.data_dir()``
    (``$CUTROOM_BENCH_DATA`` where it is set, e.g. to a copy elsewhere), else the shared
    folder beside the repository; none that is ``folder`` itself or missing."""
    folder = Path(folder).resolve()
    for shared in (shared_data.data_dir(), shared_data.DEFAULT_DATA_DIR.resolve()):
        if shared.is_dir() and shared != folder:
            return [shared]
    return []


LOO_ROWS = {
    "default/loo": "default settings chosen from tuning.GRID on the other takes",
    "tried/loo": "the same with the options tried and not shipped (tuning.TRIED) in the grid",
    "adapted/loo": "default adapted (motionlib.adapt) to the other takes of the same label "
                   "source as examples, from the settings of default/loo",
    "ruptures/loo": "ruptures_kernel with its penalty chosen on the other takes",
}


def loo_rows(cache: list[tuning.TakeCache], tried: tuning.Selection) -> dict[str, list[dict]]:
    """The leave-one-take-out rows, one list of rows per name, for the takes of ``cache``
    that are not ``pool`` takes (in ``cache`` order).

    ``tried`` scores every choice of ``tuning.tried_grid()`` on every take of ``cache``; the
    shipped grid is its subset with each tried setting at its shipped value.
    """
    scored = [not c.pool for c in cache]
    shipped = tried.shipped().leave_one_out()
    out: dict[str, list[dict]] = {name: [] for name in LOO_ROWS}
    for name, chosen in (("default/loo", shipped), ("tried/loo", tried.leave_one_out())):
        for c, found in _compress(zip(cache, chosen, strict=True), scored):
            out[name].append(_nan_row() if found is None else _timed_row(
                lambda t, p=found[0]: detector(p)(**p).fit_predict(t).cuts, c.take,
                c.labelled.truth))
    # Adaptation starts from the zero-shot settings chosen without the take (those of
    # default/loo), not the shipped ones: they were chosen on every take, this one too.
    for c, found in _compress(zip(cache, shipped, strict=True), scored):
        examples = _examples(cache, c)
        if found is None or not examples:  # nothing to choose on or to learn from
            out["adapted/loo"].append(_nan_row())
            continue
        params = found[0]
        model = adapt.fit_cut_model(examples, base=params)
        out["adapted/loo"].append(_timed_row(
            lambda t, m=model, p=params: adapt.detect(t, m, **p).cuts, c.take, c.labelled.truth))
    out["ruptures/loo"] = list(_compress(_ruptures_loo(cache), scored))
    return out


def _compress(items, keep) -> list:
    return [item for item, k in zip(items, keep, strict=True) if k]


def _nan_row() -> dict:
    return {key: float("nan") for _, key in COLUMNS}


def _examples(cache, held_out) -> list[tuple]:
    """The other takes of ``held_out``'s label source, with their best-estimate cuts.

    A capture counts once, as a studio's reviewed take would: of its views (full skeleton,
    four channels) the one of ``held_out``'s kind if it has one, else its first.
    """
    views: dict[str, list] = {}
    for c in cache:
        if c.labelled.source == held_out.labelled.source and c.key != held_out.key:
            views.setdefault(c.key, []).append(c)
    out = []
    for same in views.values():
        c = next((v for v in same if v.labelled.kind == held_out.labelled.kind), same[0])
        out.append((c.take, c.labelled.truth[:, 1]))
    return out


RUPTURES_PENALTIES = (1.0, 2.0, 3.0, 5.0, 8.0)


def _ruptures_loo(cache) -> list[dict]:
    """ruptures_kernel with the penalty (of ``RUPTURES_PENALTIES``) best on the other takes."""
    by_penalty = [[_timed_row(lambda t, pen=pen: ruptures_kernel(t, pen), c.take,
                              c.labelled.truth) for c in cache] for pen in RUPTURES_PENALTIES]
    out = []
    for j, c in enumerate(cache):
        keep = [other.key != c.key for other in cache]
        if not any(keep):  # no other capture to choose the penalty on
            out.append(_nan_row())
            continue
        best = max(range(len(RUPTURES_PENALTIES)), key=lambda i: tuning.objective(
            [r for r, k in zip(by_penalty[i], keep, strict=True) if k]))
        out.append(by_penalty[best][j])
    return out


def _point_sets(folder: Path, out) -> None:
    """The point sets (markers and tracked joints) beside the rotation sets, each at its
    own tolerance, with ruptures in the same run (``benchmarks.quality.points``)."""
    from benchmarks.quality import points as points_quality

    print("\n# Point takes: every set per take and mean, at its tolerance", file=out)
    with contextlib.redirect_stdout(out):
        points_quality.main(["--data", str(folder)])


def main(root: Path | None = None, only: list[str] | None = None, out=None, *,
         loo: bool = False, pool: list | None = None) -> int:
    """Print a table per take and the mean tables; 0 on success, 2 without data.

    ``pool``: folders of labelled takes that leave-one-take-out also chooses on (None: the
    folder the shipped settings were chosen on, ``default_pool``).
    """
    out = out or sys.stdout
    folder = Path(root) if root else shared_data.data_dir()
    pool = default_pool(folder) if pool is None else [Path(p) for p in pool]
    for where in [folder, *pool]:
        if not where.is_dir():
            print(f"error: benchmark data folder not found: {where}", file=sys.stderr)
            return 2
    started = time.perf_counter()
    selections: list = []
    cache: list = []
    results = run(folder, only, loo=loo, log=out, selection_out=selections, pool=pool,
                  cache_out=cache)
    takes = {title(c.labelled): c.labelled for c in cache}
    if not results:
        print(f"error: no labelled take to score under {folder} (see the lines above)",
              file=sys.stderr)
        return 2
    pooled = sum(c.pool for c in selections[0].cache) if selections else 0
    print(_legend(loo, pool if pooled else [], pooled), file=out)
    for name, rows in results.items():
        print(format_table(f"\n{name} ({len(takes[name].truth)} true cuts, "
                           f"{takes[name].source})", rows), file=out)
    groups = [("full-skeleton", [n for n in results if takes[n].kind == "skeleton"]),
              ("four-channel", [n for n in results if takes[n].kind == "channels"])]
    for group, names in [*groups, ("labelled", list(results))]:
        if names:
            mean = mean_rows({n: results[n] for n in names})
            print(format_table(f"\nmean over {len(names)} {group} takes", mean), file=out)
    print("\n" + placement_summary(results, groups), file=out)
    if not only or "default" in only:
        print("\n" + placement_bound_check([(c.labelled, c.take) for c in cache]), file=out)
    if selections:
        print("\n" + out_of_sample_table(selections[0]), file=out)
    if not only or "default" in only:
        print("\n" + short_activity_check(), file=out)
        read = [(c.labelled, c.take) for c in cache]
        print("\n" + real_short_activity_check(read), file=out)
        print("\n" + short_takes_check(read), file=out)
        print("\n" + edge_activity_check(read), file=out)
        print("\n" + tempo_check(read), file=out)
        print("\n" + unmatched_choice_check(read), file=out)
        print("\n" + unmatched_guard_check(folder), file=out)
        print("\n" + long_take_check(folder), file=out)
    if (not only or "joint_distance_pca" in only) and "13_30" in takes:
        print("\n" + patent_comparison(folder), file=out)
    if not only and (folder / "points").is_dir():
        _point_sets(folder, out)
    print(f"\nwhole benchmark: {time.perf_counter() - started:.0f} s, load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}", file=out)
    return 0


def _legend(loo: bool, pool=(), pooled: int = 0) -> str:
    lines = ["Rows: registered segmenters with their default parameters (`default` uses the "
             "shipped settings,",
             f"chosen on the labelled takes under {shared_data.DEFAULT_DATA_DIR.resolve()}: "
             "in-sample for those takes,",
             "out of sample for any other), ruptures_kernel (one fixed penalty) and clasp "
             "(its defaults)."]
    if loo:
        lines.append("Rows ending in /loo were scored leave-one-take-out (a take and its "
                     "other views left out together):")
        lines += [f"  {name}: {text}" for name, text in LOO_ROWS.items()]
        if pooled:
            lines.append(f"  the other takes include {pooled} labelled takes under "
                         f"{', '.join(str(p) for p in pool)} (the pool: chosen on and "
                         "learnt from, not scored)")
    lines.append("Four-channel takes (cmu/channels4d) run only the methods that need no "
                 "skeleton.")
    return "\n".join(lines)


# CN102867300A's published run on CMU 13_30 (1-based AMC frames, first and last frame
# included as the patent lists them).
PATENT_13_30 = {
    "initial": [1, 196, 800, 1384, 1966, 2425, 2465],
    "final": [1, 208, 803, 1364, 1949, 2384, 2465],
}


def patent_comparison(root: Path) -> str:
    """joint_distance_pca's initial and final cuts on 13_30 beside the published ones."""
    from motionlib.segmenters import get_segmenter

    take = next(t for t in data.labelled_takes(root) if t.name == "13_30").read()  # the patent's take
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


