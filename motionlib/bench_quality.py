"""The segmentation quality benchmark: every method, default parameters, every labelled take.

``python -m motionlib bench-quality [--loo]``; how fast things run is measured by
``python -m motionlib bench-speed`` (``motionlib.bench_speed``).

Takes are found by ``benchdata.discover`` (every labelled take in the ``shared/data``
layout, whatever its name; four-channel takes run only the methods that need no
skeleton). Rows are the registered segmenters plus two peers from the change-point
literature, run on the same heading-invariant pose stream the default detector uses (10
joints in the body frame plus root height; ``segmenters.default.take_features``):

- ``ruptures_kernel``: ruptures ``KernelCPD`` with the RBF kernel (median-heuristic
  bandwidth), on the pose averaged to 10 Hz, minimum segment 2 s, one fixed penalty
  (``RUPTURES_PENALTY``) for every take.
- ``clasp``: claspy ``BinaryClaSPSegmentation`` with its own defaults (segment count
  learned), on the pose averaged to 30 Hz.

Both are imported only here, and only when the bench runs.

With ``--loo`` three rows are scored leave-one-take-out (``LOO_ROWS``): the default's
settings chosen from ``tuning.GRID`` without the take scored, the default adapted to the
other takes of the same label source (``motionlib.adapt``, starting from those settings
chosen without the take, since the shipped ones were chosen on it too), and ruptures with its
penalty chosen without the take; the out-of-sample score of every option of every
setting, and three short-activity checks, on synthetic takes, on the real takes with
one activity cut short (``real_short_activity_check``) and with the first or last one cut
short (``edge_activity_check``), every take played slower and quicker (``tempo_check``),
and the leave-one-take-out choice of the unmatched-poses
step's settings on such takes (``unmatched_choice_check``), follow the tables, and what
that step does on the full-skeleton takes without segment labels, which are not scored
(``unmatched_guard_check``). Each take is scored separately and the means are given per
kind of take and over all, with the placement error by kind of take
(``placement_summary``) and how close oracles that see the human cuts could place them
with what each kind of take holds (``placement_bound_check``).

Leave-one-take-out chooses on all the labelled material there is, not only on the takes
scored: ``--pool DIR`` adds the labelled takes under DIR to what settings and penalties
are chosen on and what the adaptation learns from, without scoring them. By default the
pool is the shared data the shipped settings were chosen on (``default_pool``:
``$CUTROOM_BENCH_DATA`` or ``shared/data`` beside the repository) when the takes scored
are elsewhere, so that a few new takes are scored with settings
chosen on everything else, as the shipped ones were; a pool take with the name and kind
of a take scored is not added twice. A take with no other capture to choose on gets NaN
in the /loo rows.
"""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from motionlib import adapt, benchdata, metrics, tuning
from motionlib.errors import CaptureError
from motionlib.segmenters import list_segmenters
from motionlib.segmenters.default import PLACEMENTS, Default, shipped_stage, take_features
from motionlib.segmenters.default._features import block_mean
from motionlib.segmenters.default._placement import place_stages, speed_minima

RUPTURES_PENALTY = 3.0

COLUMNS = (
    ("P@.5s", "precision@0.5s"), ("R@.5s", "recall@0.5s"), ("F1@.5s", "f1@0.5s"),
    ("P@1s", "precision@1s"), ("R@1s", "recall@1s"), ("F1@1s", "f1@1s"),
    ("edits/cut", "edits_per_cut"), ("med err s", "median_error_s"), ("in window", "in_window"),
    ("time s", "time_s"), ("cuts", "n_cuts"),
)


def _peer_pose(take, rate_hz: float) -> tuple[np.ndarray, int, int]:
    x, first = take_features(take)
    step = max(1, int(round(take.fps / rate_hz)))
    return block_mean(x, step), step, first


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
    takes, skipped = benchdata.discover(root)
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
        takes, skipped = benchdata.discover(folder)
        for line in skipped:
            print(f"pool {folder}: {line}", file=log or sys.stderr)
        fresh = [t for t in takes if (t.name, t.kind) not in seen]
        seen.update((t.name, t.kind) for t in fresh)
        out += read_takes(fresh, log, pool=True, prefix=f"pool {folder}: ")
    return out


def read_takes(takes, log=None, *, pool: bool = False, prefix: str = "") -> list:
    """``takes`` read (``tuning.TakeCache``); one whose motion cannot be read or whose
    labels do not fit it (``benchdata.LabelledTake.read``) is skipped with a line saying
    so."""
    out = []
    for t in takes:
        try:
            out.append(tuning.TakeCache(t, t.read(), pool=pool))
        except (benchdata.LabelError, CaptureError) as exc:
            print(f"{prefix}skipped {t.name} ({t.path.name}): {exc}", file=log or sys.stderr)
    return out


def default_pool(folder: Path) -> list[Path]:
    """The shared data the shipped settings were chosen on: ``benchdata.data_dir()``
    (``$CUTROOM_BENCH_DATA`` where it is set, e.g. to a copy elsewhere), else the shared
    folder beside the repository; none that is ``folder`` itself or missing."""
    folder = Path(folder).resolve()
    for shared in (benchdata.data_dir(), benchdata.DEFAULT_DATA_DIR.resolve()):
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
                lambda t, p=found[0]: Default(**p).fit_predict(t).cuts, c.take,
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


def mean_rows(results: dict[str, dict]) -> dict[str, dict]:
    """Per method present on every take, the mean of each column (NaN errors skipped)."""
    if not results:
        return {}
    names = [n for n in next(iter(results.values())) if all(n in r for r in results.values())]
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


def main(root: Path | None = None, only: list[str] | None = None, out=None, *,
         loo: bool = False, pool: list | None = None) -> int:
    """Print a table per take and the mean tables; 0 on success, 2 without data.

    ``pool``: folders of labelled takes that leave-one-take-out also chooses on (None: the
    folder the shipped settings were chosen on, ``default_pool``).
    """
    out = out or sys.stdout
    folder = Path(root) if root else benchdata.data_dir()
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
    print(f"\nwhole benchmark: {time.perf_counter() - started:.0f} s, load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}", file=out)
    return 0


def placement_summary(results: dict[str, dict], groups: list[tuple[str, list[str]]],
                      names=("default", "default/loo")) -> str:
    """Placement of the default rows by kind of take: the mean over takes of the median
    |cut - best estimate| (s), and of the share of matched cuts inside the annotators'
    transition window on takes whose labels give one ("in window")."""
    lines = ["placement by kind of take (mean over takes; 'in window': share of matched cuts "
             "inside the labelled transition window, takes with windows only):"]
    for name in names:
        parts = []
        for group, takes in groups:
            rows = [results[t][name] for t in takes if name in results[t]]
            if not rows:
                continue
            error = _nanmean([r["median_error_s"] for r in rows])
            inside = [r["in_window"] for r in rows if not math.isnan(r["in_window"])]
            share = (f", in window {_nanmean(inside):.2f} ({len(inside)} "
                     f"take{'s' if len(inside) > 1 else ''})") if inside else ""
            parts.append(f"{group} {error:.3f} s{share}")
        if parts:
            lines.append(f"  {name:<12} " + "; ".join(parts))
    return "\n".join(lines)


def placement_bound_check(read: list) -> str:
    """How close placement could come with what each kind of take holds: for every cut of
    the shipped detector matched to a human cut (within 1 s), the error of the cut as
    placed; of the best of the detector's own five estimates (peak, split, turning point,
    pause, onset: step 5), picked by an oracle that sees the human cut; and of the
    turning point (local minimum of the 3 Hz pose speed, where step 5b cuts) nearest the
    human cut among those within 1 s of the placed cut, also picked by that oracle. Each
    the mean over takes of the median |cut - best estimate|, as in the placement summary;
    with how far apart the turning points lie (median gap). Where even the oracles stay
    far from the human cuts, the motion does not hold the moment the annotators cut at.
    ``read`` as in ``real_short_activity_check``."""
    per_kind: dict[str, list] = {}
    for t, take in read:
        errors = _placement_bound(t.truth, take)
        if errors is not None:
            per_kind.setdefault(t.kind, []).append(errors)
    if not per_kind:
        return "placement bound: no labelled take with a matched cut"
    lines = ["placement bound (mean over takes of the median |cut - best estimate|; the "
             "oracles see the human cut): as placed; best of the detector's five "
             "estimates; best turning point within 1 s of the placed cut; median gap "
             "between turning points:"]
    for group, kind in (("full-skeleton", "skeleton"), ("four-channel", "channels")):
        if kind in per_kind:
            placed, best, oracle, gap = np.nanmean(per_kind[kind], axis=0)
            n = len(per_kind[kind])
            lines.append(f"  {group:<14}({n} take{'s' if n > 1 else ''}) as placed "
                         f"{placed:.3f} s, best estimate {best:.3f} s, best turning point "
                         f"{oracle:.3f} s, turning points {gap:.2f} s apart")
    return "\n".join(lines)


def _placement_bound(truth: np.ndarray, take) -> list[float] | None:
    """One take's medians for ``placement_bound_check`` (s): as placed, best estimate,
    best turning point; and the median gap between turning points. None without a
    matched cut."""
    p = Default.validate_params({})
    a = Default.analyse(take, p)
    if a is None:
        return None
    p = a.params(p)
    peaks = a.peak_frames(Default.peaks(a, p).samples)
    stages, _ = place_stages(a.x, peaks, a.fps, a.gamma, p, a.speeds)
    estimates = np.stack([peaks, *(stages[k] for k in PLACEMENTS)]) + a.first
    cuts = stages[shipped_stage(p)] + a.first
    turns = speed_minima(a.speeds[1]) + a.first
    windows = metrics.as_windows(truth)
    ci, ti = metrics.match(cuts, windows, tolerance=int(round(take.fps)))
    if not len(ci):
        return None
    mids = windows[ti, 1]
    oracle = []
    for cut, mid in zip(cuts[ci], mids, strict=True):
        near = turns[np.abs(turns - cut) <= round(take.fps)]
        oracle.append(np.abs(near - mid).min() if len(near) else abs(cut - mid))
    errors = (np.abs(cuts[ci] - mids), np.abs(estimates[:, ci] - mids).min(axis=0), oracle)
    gap = float(np.median(np.diff(turns))) if len(turns) > 1 else float("nan")
    return [float(np.median(e)) / take.fps for e in errors] + [gap / take.fps]


SHORT_S = 2.5


def short_activity_check(seeds: int = 6) -> str:
    """Recall of boundaries beside short activities on synthetic takes: zero-shot (the
    shipped settings), without its unmatched-poses step (``short_unmatched`` 0), with
    each ``short_activity`` option of ``tuning.TRIED``,
    and adapted (each take's model fitted on the other seeds' takes)."""
    from motionlib import synth

    takes = []
    for seed in range(seeds):
        take, segments = synth.generate(seed=seed, fps=60.0, duration=60.0,
                                        segment_seconds=(1.5, 6.0))
        cuts = np.asarray([s[0] for s in segments[1:]])
        lengths = np.asarray([s[1] - s[0] for s in segments]) / take.fps
        short = np.minimum(lengths[:-1], lengths[1:]) < SHORT_S
        takes.append((take, cuts, short))
    options = {f"short_activity={k:g}" + (f"/uniformity={u:g}" if u else ""):
               {"short_activity": k, "short_uniformity": u}
               for k in tuning.TRIED["short_activity"]
               for u in (0.0, *tuning.TRIED["short_uniformity"])}
    options = {"short_unmatched=0": {"short_unmatched": 0.0}, **options}
    found = {name: [0, 0] for name in ["zero-shot", *options, "adapted"]}
    for i, (take, cuts, short) in enumerate(takes):
        model = adapt.fit_cut_model([(t, c) for j, (t, c, _) in enumerate(takes) if j != i])
        runs = [("zero-shot", None, {}),
                *[(name, None, params) for name, params in options.items()],
                ("adapted", model, {})]
        for name, m, params in runs:
            detected = adapt.detect(take, m, **params).cuts
            _, ti = metrics.match(detected, cuts, tolerance=int(take.fps))
            hit = np.zeros(len(cuts), dtype=bool)
            hit[ti] = True
            found[name][0] += int(hit[short].sum())
            found[name][1] += int(short.sum())
    parts = [f"{name} {k}/{n} ({k / max(n, 1):.2f})" for name, (k, n) in found.items()]
    return (f"short activities: synthetic takes ({seeds} seeds, 60 s at 60 fps, activities "
            f"1.5-6 s), boundaries beside an activity shorter than {SHORT_S:g} s found "
            f"within 1 s: " + ", ".join(parts) + " (adapted: fitted on the other seeds)")


SHORT_REAL_S = (1.8, 2.5)


def _skeletons(read: list) -> list:
    """The (labelled take, motion) pairs of full-skeleton takes."""
    return [(t, take) for t, take in read if t.kind == "skeleton"]


def real_short_activity_check(read: list, seconds=SHORT_REAL_S) -> str:
    """Short activities in real motion: each inner activity of each full-skeleton take cut
    down to ``seconds`` (``benchdata.shortened``), and whether the detector then finds both
    of its boundaries within 1 s, how many of them, and how many false cuts it makes.
    ``read``: (labelled take, its motion) pairs, as the bench read them.

    Rows: zero-shot; zero-shot without its unmatched-poses step (``short_unmatched`` 0,
    as before that step); the optional short-activity step as the default's docstring
    suggests it (``short_activity`` 4, ``short_uniformity`` 0.3); the shorter windows
    (2-4 s) the adaptation may choose; adapted, each take's model fitted on the other
    full-skeleton takes, as they are and with each of their activities shortened the same
    way (a studio whose reviewed takes hold such activities). Synthetic short activities
    (``short_activity_check``) are easier than these: their two activities differ by
    construction and they have no transitions. With a single full-skeleton take there is
    no adapted row.
    """
    read = _skeletons(read)
    if not read:
        return "short activities, real motion: no full-skeleton take"
    options = {"zero-shot": {}, "short_unmatched=0": {"short_unmatched": 0.0},
               "short_activity=4/uniformity=0.3":
               {"short_activity": 4.0, "short_uniformity": 0.3},
               "windows 2-4 s": {"scale_min_s": 2.0, "scale_max_s": 4.0}}
    cases = {duration: [(i, k, *cut) for i, (t, take) in enumerate(read)
                        for k in range(len(t.truth) - 1)
                        if (cut := benchdata.shortened(take, t.truth, k, duration))]
             for duration in seconds}
    adapted = ["adapted"] if len(read) > 1 else []  # one take: nothing to learn from
    found = {name: {d: [0, 0, 0] for d in seconds} for name in [*options, *adapted]}
    for duration, shortened in cases.items():
        models = []
        for i in range(len(read)):
            examples = [(take, t.truth[:, 1]) for j, (t, take) in enumerate(read) if j != i]
            examples += [(take, truth[:, 1]) for j, _, take, truth in shortened if j != i]
            models.append(adapt.fit_cut_model(examples) if examples else None)
        for i, k, take, truth in shortened:
            runs = [(name, None, params) for name, params in options.items()]
            runs += [("adapted", models[i], {})] if adapted else []
            for name, model, params in runs:
                cuts = adapt.detect(take, model, **params).cuts
                ci, ti = metrics.match(cuts, truth, tolerance=int(round(take.fps)))
                hit = set(ti.tolist())
                row = found[name][duration]
                row[0] += k in hit and k + 1 in hit
                row[1] += (k in hit) + (k + 1 in hit)
                row[2] += len(cuts) - len(ci)
    head = "".join(f"{f'{d:g} s: both':>14}{'sides':>8}{'false':>7}" for d in seconds)
    lines = [f"short activities, real motion: each inner activity of the {len(read)} "
             f"full-skeleton takes cut down to {' / '.join(f'{d:g}' for d in seconds)} s by "
             f"removing its middle ({' / '.join(str(len(cases[d])) for d in seconds)} "
             f"cases); both of its boundaries found within 1 s, its boundaries found, false "
             f"cuts in the take (adapted: fitted on the other takes, as they are and "
             f"shortened):", f"  {'':<34}{head}"]
    for name, rows in found.items():
        cells = "".join(f"{f'{b}/{len(cases[d])}':>14}{f'{s}/{2 * len(cases[d])}':>8}{f:>7}"
                        for d, (b, s, f) in rows.items())
        lines.append(f"  {name:<34}{cells}")
    return "\n".join(lines)


THROUGHOUT_S = (2.5, 3.0, 4.0)
# How step 4c's settings (``short_unmatched`` and the half-width of its two cuts) are
# chosen: the options, and the cut-down takes they are chosen and scored on.
UNMATCHED_LEVELS = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0)
UNMATCHED_HALVES = (0.75, 1.0, 1.25)
UNMATCHED_INNER_S = (1.5, 1.8, 2.2, 2.5, 3.0)
UNMATCHED_THROUGHOUT_S = (2.5, 3.0, 4.0, 5.0)


def unmatched_choice_check(read: list) -> str:
    """How the unmatched-poses step's settings (``segmenters.default`` step 4c) are
    chosen, and how that choice scores on takes it was not chosen on.

    Material: every take as it is (full-skeleton and four-channel), and each
    full-skeleton take with each inner activity cut down to ``UNMATCHED_INNER_S``
    (``benchdata.shortened``, one at a time) and with all of them cut down to
    ``UNMATCHED_THROUGHOUT_S`` (``benchdata.shortened_throughout``). A setting's score
    on some material is the mean over the three families (as they are, one cut down,
    all cut down) of the mean F1@1 s; the first of equal settings (off first) wins.
    Each full-skeleton capture is left out in turn (its four-channel view with it): the
    setting is chosen on everything else, and scored on the left-out take's material,
    beside the step off. ``read``: (labelled take, motion) pairs, as the bench read them.
    """
    from motionlib.segmenters.default._unmatched import UNMATCHED_HALF_S, unmatched_peaks

    skeletons = _skeletons(read)
    if not skeletons:
        return "unmatched-poses step: no full-skeleton take to choose its settings on"
    material = [(t.name, "as is", take, t.truth, None) for t, take in read if len(t.truth)]
    for t, take in skeletons:
        for k in range(len(t.truth) - 1):
            for seconds in UNMATCHED_INNER_S:
                cut = benchdata.shortened(take, t.truth, k, seconds)
                if cut is not None:
                    material.append((t.name, "one cut down", *cut, k))
        for seconds in UNMATCHED_THROUGHOUT_S:
            material.append((t.name, "all cut down",
                             *benchdata.shortened_throughout(take, t.truth, seconds), None))
    settings = [(0.0, UNMATCHED_HALF_S)] + [(level, half) for level in UNMATCHED_LEVELS
                                            if level > 0 for half in UNMATCHED_HALVES]
    p = Default.validate_params({})
    ratios: list[float] = []  # each firing's level / take median, without the guard
    scores = {}  # (setting, material index) -> (F1@1 s, both sides of the short one found)
    for i, (_, _, take, truth, k) in enumerate(material):
        analysis = Default.analyse(take, p)
        if analysis is None:
            continue
        peaks, strength = Default.window_peaks(analysis, p)
        ratios += unmatched_ratios(analysis, peaks, p)
        for level, half in settings:
            kept = peaks if level == 0 else unmatched_peaks(
                analysis, peaks, strength, {**p, "short_unmatched": level}, half_s=half)[0]
            stages, _ = place_stages(analysis.x, analysis.peak_frames(kept), analysis.fps,
                                     analysis.gamma, p)
            cuts = stages[shipped_stage(p)] + analysis.first
            _, ti = metrics.match(cuts, truth, tolerance=int(round(take.fps)))
            scores[(level, half), i] = (
                metrics.evaluate(cuts, truth, fps=take.fps)["f1@1s"],
                k is not None and k in ti and k + 1 in ti)

    def score(setting, used) -> float:
        families: dict[str, list[float]] = {}
        for i in used:
            if (setting, i) in scores:
                families.setdefault(material[i][1], []).append(scores[setting, i][0])
        return round(float(np.mean([np.mean(v) for v in families.values()])), 9) \
            if families else -math.inf

    def family(setting, used, name) -> tuple[float, int, int]:
        rows = [scores[setting, i] for i in used
                if material[i][1] == name and (setting, i) in scores]
        return (float(np.mean([r[0] for r in rows])) if rows else math.nan,
                sum(r[1] for r in rows), len(rows))

    def label(setting) -> str:
        return "off" if setting[0] == 0 else f"{setting[0]:g} / {setting[1]:g} s"

    everything = range(len(material))
    lines = [f"unmatched-poses step (short_unmatched / half-width of its two cuts), chosen "
             f"leave-one-take-out: each full-skeleton take left out, the setting chosen on "
             f"the other takes as they are, with one inner activity cut down to "
             f"{' / '.join(f'{s:g}' for s in UNMATCHED_INNER_S)} s and with all cut down to "
             f"{' / '.join(f'{s:g}' for s in UNMATCHED_THROUGHOUT_S)} s (mean of the three "
             f"families' mean F1@1 s), and scored on the take left out:",
             f"  {'left out':<10}{'chosen':>14}  {'as is F1':>9}{'one cut down: F1':>18}"
             f"{'both':>8}{'all cut down F1':>17}"]
    totals = {"chosen": [], "off": []}
    for t, _ in skeletons:
        used = [i for i in everything if material[i][0] != t.name]
        held = [i for i in everything if material[i][0] == t.name]
        best = max(settings, key=lambda s: score(s, used))
        for name, setting in (("chosen", best), ("off", settings[0])):
            cells = (family(setting, held, "as is")[0], *family(setting, held, "one cut down"),
                     family(setting, held, "all cut down")[0])
            totals[name].append(cells)
            if name == "chosen" or setting != best:
                lines.append(_unmatched_row(t.name if name == "chosen" else "",
                                            label(setting), cells))
    for name, rows in totals.items():
        lines.append(_unmatched_row("all" if name == "chosen" else "", name, (
            float(np.mean([r[0] for r in rows])), float(np.mean([r[1] for r in rows])),
            sum(r[2] for r in rows), sum(r[3] for r in rows),
            float(np.mean([r[4] for r in rows])))))
    best = max(settings, key=lambda s: score(s, everything))
    lines.append(f"  chosen on all: {label(best)}; shipped: short_unmatched "
                 f"{Default.params['short_unmatched'].default:g}, half-width "
                 f"{UNMATCHED_HALF_S:g} s")
    lines.append(f"  {_guard_line(ratios)}")
    return "\n".join(lines)


def unmatched_ratios(analysis, peaks: np.ndarray, p: dict) -> list[float]:
    """For each kept peak the unmatched-poses step (at the shipped settings) replaces
    without its take-median guard, the level of the stretch it fires on over the take's
    median (``segmenters.default.unmatched_firings``)."""
    from motionlib.segmenters.default._unmatched import unmatched_firings

    if p["short_unmatched"] <= 0:
        return []
    firings, median = unmatched_firings(analysis, peaks, p)
    return [at / max(median, 1e-12) for _, at in firings.values()
            if at >= p["short_unmatched"]]


def _guard_line(ratios: list[float]) -> str:
    from motionlib.segmenters.default._unmatched import UNMATCHED_RELATIVE

    if not ratios:
        return "take-median guard: the step fires nowhere on this material"
    kept = sum(r >= UNMATCHED_RELATIVE for r in ratios)
    return (f"take-median guard (stretch at least {UNMATCHED_RELATIVE:g} x the take's median "
            f"as well): of the {len(ratios)} firings on this material without it, {kept} "
            f"kept; level / take median from {min(ratios):.1f} (median "
            f"{float(np.median(ratios)):.1f})")


def unmatched_guard_check(folder: Path) -> str:
    """The unmatched-poses step on the full-skeleton takes without segment labels
    (``benchdata.unlabelled_motion``): the default detector's number of cuts as shipped
    and with the step off, and, for each stretch the step would fire on without its
    take-median guard, its level over the take's median (the guard keeps it from
    ``UNMATCHED_RELATIVE`` on). Nothing is scored (there are no labels): a take that does
    not repeat itself (boxing, dance) is where the guard acts, and these show where it
    does."""
    import motionlib
    from motionlib.segmenters.default._unmatched import UNMATCHED_RELATIVE

    takes = benchdata.unlabelled_motion(folder)
    if not takes:
        return "unmatched-poses step on takes without labels: none under the data folder"
    p = Default.validate_params({})
    rows = []
    for path, asf in takes:
        try:
            take = motionlib.read(path, asf=asf)
        except CaptureError as exc:
            rows.append(f"  {path.stem:<10} skipped: {exc}")
            continue
        cache = tuning.TakeCache(None, take)  # one analysis for the three questions
        counts = [len(cache.cuts(params)) for params in ({}, {"short_unmatched": 0.0})]
        analysis = cache.analysis(p)
        ratios = [] if analysis is None else unmatched_ratios(
            analysis, Default.window_peaks(analysis, p)[0], p)
        firings = ", ".join(f"{r:.1f}x ({'kept' if r >= UNMATCHED_RELATIVE else 'not'})"
                            for r in ratios)
        rows.append(f"  {path.stem:<10}{take.n_frames / take.fps:>7.1f}{counts[0]:>9}"
                    f"{counts[1]:>10}   {firings or '-'}")
    return "\n".join([
        f"unmatched-poses step on the full-skeleton takes without segment labels (not "
        f"scored): cuts as shipped and with the step off; each stretch the step fires on "
        f"without its take-median guard, its level / the take's median, kept from "
        f"{UNMATCHED_RELATIVE:g}x:",
        f"  {'take':<10}{'s':>7}{'shipped':>9}{'step off':>10}   firings", *rows])


# Cuts and true cuts this close (s) to a join of two takes are not scored: what lies
# there (the end of one take, the start of the other) is neither take's activity.
JOIN_S = 2.0


def long_take_check(folder: Path) -> str:
    """Long takes made of several: the full-skeleton AMC takes of one skeleton (ASF), with
    labels and without, joined end to end two at a time in both orders and all together;
    each labelled part scored in its own span against its own cuts, beside the take on its
    own, both without what lies within ``JOIN_S`` of a join. The detector's kernel width
    and levels are the take's, so what else a take holds can change its cuts; this shows
    how much (a studio's takes are long and mixed, the labelled ones here 20-40 s)."""
    import motionlib

    labelled = [t for t in benchdata.discover(folder, channels=False, bvh=False)[0]
                if t.asf is not None and t.path.suffix == ".amc"]
    groups: dict[Path, list] = {}
    for t in labelled:
        groups.setdefault(Path(t.asf).resolve(), []).append((t.name, t.path, t))
    for path, asf in benchdata.unlabelled_motion(folder):
        if asf is not None and Path(asf).resolve() in groups:
            groups[Path(asf).resolve()].append((path.stem, path, None))
    lines, joined_rows, alone_rows = [], [], []
    for asf, members in groups.items():
        if len(members) < 2:
            continue
        try:
            parts = [(name, motionlib.read(path, asf=asf), t) for name, path, t in members]
        except CaptureError as exc:
            lines.append(f"  skipped {asf.name}: {exc}")
            continue
        joins = [[a, b] for a in parts for b in parts if a is not b and (a[2] or b[2])]
        if len(parts) > 2:
            joins.append(list(parts))
        alone = {name: Default().fit_predict(take).cuts for name, take, t in parts if t}
        for join in joins:
            for name, joined, own in _part_rows(join, alone):
                lines.append(f"  {' + '.join(n for n, _, _ in join):<26}{name:<8}"
                             f"{joined['f1@1s']:>7.3f}{joined['edits_per_cut']:>7.2f}"
                             f"{own['f1@1s']:>13.3f}{own['edits_per_cut']:>7.2f}")
                joined_rows.append(joined)
                alone_rows.append(own)
    if not joined_rows:
        return "long takes: no skeleton with two AMC takes, one of them labelled, here"
    mean = mean_rows({i: {"joined": j, "alone": a}
                      for i, (j, a) in enumerate(zip(joined_rows, alone_rows, strict=True))})
    return "\n".join([
        "long takes, real motion: the full-skeleton AMC takes of one skeleton joined end to "
        "end (two at a time in both orders, and all); each labelled part scored in its own "
        f"span, beside the take alone, both without cuts and true cuts within {JOIN_S:g} s "
        "of a join:",
        f"  {'joined':<26}{'part':<8}{'F1@1s':>7}{'edits':>7}{'alone: F1@1s':>13}{'edits':>7}",
        *lines,
        f"  mean over {len(joined_rows)} parts: joined F1@1s {mean['joined']['f1@1s']:.3f}, "
        f"edits {mean['joined']['edits_per_cut']:.2f}; alone {mean['alone']['f1@1s']:.3f}, "
        f"{mean['alone']['edits_per_cut']:.2f}"])


def _part_rows(parts, alone: dict) -> list[tuple[str, dict, dict]]:
    """The default detector on ``parts`` (name, take, labelled take or None) joined end to
    end. Per labelled part, ``metrics.evaluate`` of the joined take's cuts in its span and
    of its cuts alone (``alone[name]``), both against its own cuts and without what lies
    within ``JOIN_S`` of a join at its ends."""
    joined = benchdata.with_channels(
        parts[0][1], np.concatenate([take.channels for _, take, _ in parts]))
    cuts = Default().fit_predict(joined).cuts
    out, start = [], 0
    for i, (name, take, labelled) in enumerate(parts):
        n = take.n_frames
        if labelled is not None:
            gap = int(round(JOIN_S * take.fps))
            lo, hi = (gap if i else 0), (n - gap if i + 1 < len(parts) else n)
            truth = labelled.truth[(labelled.truth[:, 1] >= lo) & (labelled.truth[:, 1] < hi)]
            rows = []
            for found in (cuts - start, alone[name]):
                found = found[(found >= lo) & (found < hi)]
                rows.append(metrics.evaluate(found, truth, fps=take.fps))
            out.append((name, *rows))
        start += n
    return out


def short_takes_check(read: list, seconds=THROUGHOUT_S) -> str:
    """Takes made of short activities throughout: every inner activity of each
    full-skeleton take cut down to ``seconds`` (``benchdata.shortened_throughout``), and
    the mean F1@1 s and edits per true cut of the zero-shot detector and of the adapted
    one, fitted on the other takes cut down the same way (a studio whose reviewed takes
    are like that). ``read`` as in ``real_short_activity_check``; with a single
    full-skeleton take there is no adapted row.
    """
    read = _skeletons(read)
    if not read:
        return "short activities throughout a take: no full-skeleton take"
    rows = {"zero-shot": [], **({"adapted": []} if len(read) > 1 else {})}
    for duration in seconds:
        built = [benchdata.shortened_throughout(take, t.truth, duration) for t, take in read]
        scores = {name: [] for name in rows}
        for i, (take, truth) in enumerate(built):
            examples = [(other, cuts[:, 1]) for j, (other, cuts) in enumerate(built) if j != i]
            models = {"zero-shot": None, "adapted": adapt.fit_cut_model(examples)
                      if "adapted" in rows else None}
            for name in rows:
                cuts = adapt.detect(take, models[name]).cuts
                scores[name].append(metrics.evaluate(cuts, truth, fps=take.fps))
        for name in rows:
            rows[name].append([np.mean([r[key] for r in scores[name]])
                               for key in ("f1@1s", "edits_per_cut")])
    head = "".join(f"{f'{d:g} s: F1@1s':>16}{'edits':>7}" for d in seconds)
    lines = [f"short activities throughout a take, real motion: every inner activity of the "
             f"{len(read)} full-skeleton takes cut down to "
             f"{' / '.join(f'{d:g}' for d in seconds)} s by removing its middle; mean F1@1 s "
             f"and edits per true cut (adapted: fitted on the other takes cut down the same "
             f"way):", f"  {'':<12}{head}"]
    for name, cells in rows.items():
        lines.append(f"  {name:<12}" + "".join(f"{f1:>16.3f}{edits:>7.2f}"
                                               for f1, edits in cells))
    return "\n".join(lines)


def _unmatched_row(name: str, setting: str, cells: tuple) -> str:
    as_is, f1, both, n, all_cut = cells
    return (f"  {name:<10}{setting:>14}  {as_is:>9.3f}{f1:>18.3f}{f'{both}/{n}':>8}"
            f"{all_cut:>17.3f}")


TEMPO_SPEEDS = (0.8, 0.9, 1.0, 1.1, 1.25)


def tempo_check(read: list, speeds=TEMPO_SPEEDS) -> str:
    """Takes played slower and quicker (``benchdata.played_at``): each labelled take as if
    performed at ``speeds`` times its pace, its true cuts moved with it, scored as
    shipped and with the ``tempo`` setting (time settings scaled by the take's own
    movement cycle). A studio's performers do not all move at the pace of the takes the
    settings were chosen on; this shows how much that costs."""
    if not read:
        return "tempo: no labelled take"
    settings = (("shipped", {}), ("tempo", {"tempo": True}))
    per_take: dict[tuple, dict] = {}  # (kind, name) -> (setting, speed) -> row
    for t, take in read:
        rows = per_take.setdefault((t.kind, t.name), {})
        for speed in speeds:
            played, truth = (take, t.truth) if speed == 1.0 else \
                benchdata.played_at(take, t.truth, speed)
            for setting, params in settings:
                cuts = Default(**params).fit_predict(played).cuts
                rows[(setting, speed)] = metrics.evaluate(cuts, truth, fps=take.fps)
    head = "".join(f"{f'x{s:g}: F1@1s':>14}{'edits':>7}{'err s':>7}" for s in speeds)
    lines = [f"tempo: each labelled take played at {' / '.join(f'{s:g}' for s in speeds)} "
             f"times its pace (its cuts moved with it); mean F1@1 s, edits per true cut and "
             f"median placement error, as shipped and with tempo on:",
             f"  {'':<28}{head}"]
    for group, kind in (("full-skeleton", "skeleton"), ("four-channel", "channels")):
        mean = mean_rows({key: rows for key, rows in per_take.items() if key[0] == kind})
        if not mean:
            continue
        for setting, _ in settings:
            cells = "".join(f"{m['f1@1s']:>14.3f}{m['edits_per_cut']:>7.2f}"
                            f"{m['median_error_s']:>7.2f}"
                            for m in (mean[(setting, speed)] for speed in speeds))
            lines.append(f"  {group + ', ' + setting:<28}{cells}")
    return "\n".join(lines)


EDGE_REAL_S = (1.5, 1.8, 2.5)


def edge_activity_check(read: list, seconds=EDGE_REAL_S) -> str:
    """Short activities at the ends of real takes: the first and the last activity of each
    full-skeleton take cut down to ``seconds`` (``benchdata.trimmed``), and whether the
    zero-shot detector then finds its boundary within 1 s, and how many false cuts it
    makes. The novelty windows there see the take mirrored at its end. ``read`` as in
    ``real_short_activity_check``; a take without a cut has no such boundary and is left
    out.
    """
    read = [(t, take) for t, take in _skeletons(read) if len(t.truth)]
    if not read:
        return "short activities at the ends of a take: no full-skeleton take with a cut"
    cells = []
    for duration in seconds:
        found = cases = false = 0
        for t, take in read:
            for side, index in (("first", 0), ("last", -1)):
                cut = benchdata.trimmed(take, t.truth, side, duration)
                if cut is None:
                    continue
                short, truth = cut
                cuts = adapt.detect(short).cuts
                ci, _ = metrics.match(cuts, truth, tolerance=int(round(short.fps)))
                cases += 1
                found += bool(len(cuts)) and \
                    np.abs(cuts - truth[index, 1]).min() <= round(short.fps)
                false += len(cuts) - len(ci)
        cells.append(f"{duration:g} s {found}/{cases} (false cuts {false})")
    return (f"short activities at the ends of a take, real motion: the first and the last "
            f"activity of each of the {len(read)} full-skeleton takes cut down by dropping "
            f"the take's first or last frames; its boundary found within 1 s, zero-shot: "
            + ", ".join(cells))


def out_of_sample_table(tried: tuning.Selection) -> str:
    """The default's settings: what was chosen on all takes, and how each option of each
    setting scores leave-one-take-out (the others still chosen without the take), first
    in the shipped grid, then for the options tried and not shipped (``tuning.TRIED``,
    chosen with all of ``tuning.tried_grid()``)."""
    selection = tried.shipped()
    chosen = selection.chosen()
    pooled = sum(c.pool for c in selection.cache)
    lines = [f"default settings chosen on all {len(selection.cache)} takes"
             + (f" ({pooled} of them from the pool)" if pooled else "") + " from tuning.GRID: "
             + ", ".join(f"{k}={v:g}" if not isinstance(v, bool) else f"{k}={v}"
                         for k, v in chosen.items()),
             "out of sample (leave-one-take-out) with one setting imposed:",
             f"  {'setting':<15}{'value':>12}{'F1@1s':>9}{'edits/cut':>11}"]
    for key, value, f1, edits in tuning.out_of_sample(selection):
        lines.append(f"  {key:<15}{str(value):>12}{f1:>9.3f}{edits:>11.3f}")
    lines.append("  tried, not shipped (the other settings chosen from the grid with them):")
    grid = tuning.tried_grid()
    for key, value, f1, edits in tuning.out_of_sample(tried, {k: grid[k] for k in tuning.TRIED}):
        lines.append(f"  {key:<15}{str(value):>12}{f1:>9.3f}{edits:>11.3f}")
    lines.append("  how the choice is made (every setting chosen the same way):")
    for name, f1, edits in tuning.objectives(selection):
        shipped = " (shipped)" if name == "F1@1s first" else ""
        lines.append(f"  {'objective':<15}{name:>12}{f1:>9.3f}{edits:>11.3f}{shipped}")
    return "\n".join(lines + ["", source_table(selection)])


def source_table(selection: tuning.Selection) -> str:
    """The default's settings chosen on the other label sources only, scored on each
    source, beside leave-one-take-out (which chooses on the same source's other takes
    too)."""
    rows = tuning.by_source(selection)
    lines = ["settings chosen on the other label sources only (leave-one-source-out) and "
             "leave-one-take-out, mean over each source's takes:",
             f"  {'source':<12}{'takes':>6}{'other sources: F1@1s':>22}{'edits':>7}"
             f"{'med err':>8}{'loo: F1@1s':>12}{'edits':>7}{'med err':>8}"]
    for source, n, other, loo in rows:
        lines.append(f"  {source:<12}{n:>6}{other['f1@1s']:>22.3f}{other['edits_per_cut']:>7.3f}"
                     f"{other['median_error_s']:>8.3f}{loo['f1@1s']:>12.3f}"
                     f"{loo['edits_per_cut']:>7.3f}{loo['median_error_s']:>8.3f}")
    return "\n".join(lines)


def _legend(loo: bool, pool=(), pooled: int = 0) -> str:
    lines = ["Rows: registered segmenters with their default parameters (`default` uses the "
             "shipped settings,",
             f"chosen on the labelled takes under {benchdata.DEFAULT_DATA_DIR.resolve()}: "
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

    take = next(t for t in benchdata.labelled_takes(root) if t.name == "13_30").read()  # the patent's take
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


def add_bench_quality(subparsers) -> None:
    """Register ``python -m motionlib bench-quality`` (see ``motionlib.cli``)."""
    # ``bench`` is the name studios already script against; ``bench-quality`` says what it
    # measures beside ``bench-speed``.
    p = subparsers.add_parser(
        "bench-quality", aliases=["bench"],
        help="benchmark how well the segmenters cut the labelled CMU takes",
        description="Every segmenter (default parameters) and two change-point peers on "
                    "every labelled take: a table per take and the mean.",
    )
    p.add_argument("--data", help="benchmark data folder (default: $CUTROOM_BENCH_DATA or "
                                 "../shared/data)")
    p.add_argument("--method", action="append", help="only this row (repeatable)")
    p.add_argument("--loo", action="store_true",
                   help="also score leave-one-take-out: the default settings chosen, the "
                        "adapted model fitted and the ruptures penalty chosen without the "
                        "take scored")
    p.add_argument("--pool", action="append", metavar="DIR",
                   help="with --loo, also choose on and learn from the labelled takes under "
                        "DIR, without scoring them (repeatable; default: the folder the "
                        "shipped settings were chosen on, when --data is another)")
    p.add_argument("--no-pool", action="store_true",
                   help="with --loo, choose on the other takes under --data only")
    p.set_defaults(handler=lambda args: main(
        args.data, args.method, loo=args.loo, pool=[] if args.no_pool else args.pool))
