"""The first format of a studio's cut model (format 1): the default detector's own
settings adapted to example takes, kept so that models stored in it load and detect as
they did (``motionlib.adapt`` learns format 2 now).

Given example takes with their human cuts, :func:`fit_threshold_model` learns a
:class:`ThresholdModel`, and :func:`detect_threshold` runs the default detector with it.
It uses only the detector's public pipeline (``segmenters.default``: ``analyse``,
``peaks``, ``candidates``, ``place``).

What is learnt, step by step (each from all examples together, never per take); every
step starts from the zero-shot setting and leaves it only when the examples clearly say
so:

1. *Minimum segment.* The shortest human segment bounds how close two cuts may be:
   ``min_segment_s`` becomes 0.75 x the shortest example segment when that is shorter
   than the zero-shot one (never below 0.5 s).
2. *How many cuts, and at which scale.* Every novelty peak of every example is computed
   once (``candidates``; a zero-shot cut counted where the detector places it), and the
   ``prominence`` of :data:`PROMINENCE_GRID` whose peaks match the human cuts with the
   fewest review edits (deletes and inserts, one-to-one within 1 s; every edit weighs
   the same in every example) is kept, less a prior cost of moving away from the
   zero-shot prominence. The prior's strength is fixed with one or two examples and,
   from :data:`PRIOR_CV_TAKES` on, chosen by leave-one-example-take-out, so examples that
   agree move the count and a single odd take does not. The count is chosen by review
   edits, not F1, because a reviewer gains from a weak candidate only when it is true
   more often than not. When an example activity is shorter than the zero-shot shortest
   window, the shorter windows of :data:`WINDOW_OPTIONS` compete the same way.
3. *Where.* Each placement step of the detector is an anchor; the anchor and median
   shift that fit the human cuts best replace the zero-shot placement only when enough
   example cuts matched and the error drops clearly (:data:`PLACEMENT_MIN_CUTS`,
   :data:`PLACEMENT_GAIN`): annotators who mark the onset of the next activity cut a
   steady time after the statistical change, and a handful of cuts cannot show that.

Each example take is analysed once and then dropped (only its peaks and offsets are
kept), so a project's examples can be read one at a time. What is kept of an example, its
*study*, can be stored (``fit_threshold_model(..., studies=...)``, :class:`Example` with a key):
refitting after one more reviewed take then reads and analyses that take only, and
learns the same model. How each choice was made and how it scores is recorded in
``docs/detector/adaptation.md``.

Pure numpy/scipy, no Django; a stored ``ThresholdModel.to_json()`` still loads.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Protocol

import numpy as np

from motionlib import metrics
from motionlib.adapt._examples import ExampleError
from motionlib.errors import InputError
from motionlib.points import segmenter_input
from motionlib.segmenters import default
from motionlib.segmenters.base import Segmentation
from motionlib.segmenters.default import PLACEMENTS, Default, Peaks, shipped_stage

FORMAT = 1
# Fields added to format 1 after its first models were stored, with the value that keeps
# those models detecting as they did (no prominence test).
OPTIONAL_FIELDS = {"prominence": 0.0}
MIN_SEGMENT_S = 0.5
MIN_SEGMENT_FACTOR = 0.75
# A placement other than the zero-shot one needs this many matched example cuts and must
# cut the median placement error by this fraction and this many seconds: few cuts or a
# small gain are noise, and a wrong shift moves every cut.
PLACEMENT_MIN_CUTS = 6
PLACEMENT_GAIN = (0.2, 0.03)
MATCH_S = 1.0


@dataclass(frozen=True)
class ThresholdModel:
    """What the default detector learnt from example takes with human cuts.

    n_takes : example takes it learnt from.
    n_cuts : human cuts it learnt from.
    threshold : novelty peak height (mean MMD²) for a cut.
    prominence : novelty peak prominence (MMD²) for a cut.
    min_segment_s : minimum time between two cuts (s).
    scale_min_s, scale_max_s : shortest and longest novelty window (s).
    placement : the placement step the cut is taken from (``segmenters.default.PLACEMENTS``:
        "split", "turn", "pause" or "onset").
    offset_s : signed shift added to every placed cut (s); positive moves cuts later.
    """

    n_takes: int
    n_cuts: int
    threshold: float
    prominence: float
    min_segment_s: float
    scale_min_s: float
    scale_max_s: float
    placement: str
    offset_s: float

    def params(self) -> dict[str, float]:
        """The default segmenter's parameters this model sets."""
        return {"threshold": self.threshold, "prominence": self.prominence,
                "min_segment_s": self.min_segment_s, "scale_min_s": self.scale_min_s,
                "scale_max_s": self.scale_max_s}

    def to_json(self) -> str:
        """Stable JSON text (sorted keys) with ``"format": 1``."""
        return json.dumps({"format": FORMAT, **asdict(self)}, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> ThresholdModel:
        """Parse ``to_json`` output; ValueError naming what is wrong."""
        try:
            data = json.loads(text)
        except (TypeError, json.JSONDecodeError) as exc:
            raise InputError(f"cut model: not JSON: {exc}") from None
        if not isinstance(data, dict):
            raise InputError(f"cut model: expected a JSON object, got {type(data).__name__}")
        if data.get("format") != FORMAT:
            raise InputError(f"cut model: unsupported format {data.get('format')!r} "
                             f"(expected {FORMAT})")
        values = {}
        for name, kind in (("n_takes", int), ("n_cuts", int), ("threshold", float),
                           ("prominence", float), ("min_segment_s", float),
                           ("scale_min_s", float), ("scale_max_s", float),
                           ("offset_s", float)):
            value = data.get(name, OPTIONAL_FIELDS.get(name))
            ok = isinstance(value, int | float) and not isinstance(value, bool)
            if not ok or not math.isfinite(value) or (kind is int and value != int(value)):
                raise InputError(f"cut model: {name} must be a finite "
                                 f"{'integer' if kind is int else 'number'}, got {value!r}")
            values[name] = kind(value)
        if data.get("placement") not in PLACEMENTS:
            raise InputError(f"cut model: placement must be one of {', '.join(PLACEMENTS)}, "
                             f"got {data.get('placement')!r}")
        return cls(**values, placement=data["placement"])


def _where(take) -> str:
    return os.path.basename(take.path) if getattr(take, "path", None) else take.name


def _checked_cuts(take, cuts) -> np.ndarray:
    """Cuts as sorted unique int frames inside the take; ExampleError naming a bad one."""
    out = []
    for value in cuts:
        number = float(value)
        if not math.isfinite(number) or number != int(number):
            raise ExampleError(f"{_where(take)}: cut {value!r} is not a whole frame")
        if not 0 < int(number) < take.n_frames:
            raise ExampleError(f"{_where(take)}: cut {int(number)} is outside the take "
                               f"(frames 1 to {take.n_frames - 1} can start a segment)")
        out.append(int(number))
    return np.unique(np.asarray(out, dtype=np.int64))


@dataclass(frozen=True)
class Example:
    """An example take described before it is read, so that a stored study can stand in
    for reading and analysing it (``fit_cut_model``'s ``studies``).

    name : how an error names the take; cuts : its human cuts (0-based take frames);
    fps, n_frames : the take's frame rate and length; read : returns the take;
    key : identifies the take's content (e.g. its file's checksum), or None to never
    store its study.
    """

    name: str
    cuts: Sequence[int]
    fps: float
    n_frames: int
    read: Callable[[], object]
    key: str | None = None


class Studies(Protocol):
    """Where ``fit_cut_model`` keeps what it learnt from each example (its *study*).

    A study is a dict of numpy arrays; ``study_key`` names the example's cuts and the
    detector settings it was made with, and a store returns a study only for the same
    ``study_key`` (a store may keep one study per ``example_key``).
    """

    def load(self, example_key: str, study_key: str) -> dict[str, np.ndarray] | None: ...

    def save(self, example_key: str, study_key: str, arrays: dict[str, np.ndarray]) -> None: ...


class MemoryStudies:
    """``Studies`` in a dict: one study per example, for as long as the object lives."""

    def __init__(self):
        self.items: dict[str, tuple[str, dict[str, np.ndarray]]] = {}

    def load(self, example_key, study_key):
        stored = self.items.get(example_key)
        return stored[1] if stored is not None and stored[0] == study_key else None

    def save(self, example_key, study_key, arrays):
        self.items[example_key] = (study_key, arrays)


# Bump when what a study holds, or how the detector computes it, changes: every stored
# study then misses once and is made again.
STUDY_VERSION = 3


def fit_threshold_model(examples: Sequence, *, studies: Studies | None = None,
                  base: dict | None = None) -> ThresholdModel:
    """Adapt the default detector to example takes with human cuts.

    Parameters
    ----------
    examples : sequence of (take, cuts), or of :class:`Example`; cuts are 0-based take
        frames where a new segment starts (a take with no cut is a valid example: one
        activity throughout). A take is a ``motionlib.Take`` (or anything
        ``segmenters.default.take_features`` reads); each is analysed once, in order,
        and not kept.
    studies : where what was learnt from each :class:`Example` with a ``key`` is kept.
        An example whose study for the same cuts and settings is stored there is
        neither read nor analysed, so refitting after one more reviewed take analyses
        that one take; the model is the same as without ``studies``.
    base : the ``default`` segmenter's parameters adaptation starts from (its zero-shot
        settings when None); detect with the same parameters (``detect(take, model,
        **base)``). The benchmark passes the settings chosen without the take it scores.

    Returns
    -------
    ThresholdModel; one example is enough, more make each step surer.

    Raises
    ------
    ExampleError (a ValueError) naming the take and the value: an empty example list, a cut
    outside the take, a take too short to analyse.
    """
    if len(examples) == 0:
        raise ExampleError("no example takes to learn from")
    p = Default.validate_params(base or {})
    checked = [(example, _checked_cuts(example, example.cuts))
               for example in map(_as_example, examples)]
    shortest = _shortest_segment(checked)
    if shortest is not None:  # only ever shorter: a longer one would hide short activities
        p["min_segment_s"] = float(np.clip(MIN_SEGMENT_FACTOR * shortest, MIN_SEGMENT_S,
                                           p["min_segment_s"]))
    # One pass over the takes, keeping only peaks and placement offsets: a project's
    # examples need not all be held in memory with their pose streams.
    zero_windows = (p["scale_min_s"], p["scale_max_s"])
    options = _window_options(zero_windows, shortest)
    peaks = {w: [] for w in [*options, "placed"]}
    residuals = {name: [] for name in PLACEMENTS}
    for example, cuts in checked:
        study = _study(example, cuts, p, options, studies)
        tol = int(round(MATCH_S * example.fps))
        for name in PLACEMENTS:
            residuals[name].extend(study[f"residual_{name}"].tolist())
        for windows in ["placed", *options[1:]]:
            label = _label(windows)
            peaks[windows].append((study[f"{label}_frames"], study[f"{label}_prominence"],
                                   cuts, tol, study[f"{label}_raw"]))
    windows = zero_windows
    if len(options) > 1:
        # Windows compete on unplaced peaks (placing them all would cost a detection each);
        # the count is then chosen where the chosen windows' cuts really land.
        peaks[zero_windows] = [_unplaced(take_peaks) for take_peaks in peaks["placed"]]
        scores = {w: _count(peaks[w], p["prominence"])[0] - (w != zero_windows) * WINDOW_PRIOR
                  for w in options}
        windows = max(options, key=lambda w: scores[w])
    _, prominence = _count(peaks["placed"] if windows == zero_windows else peaks[windows],
                           p["prominence"])
    placement, offset = _placement(residuals, shipped_stage(p))
    return ThresholdModel(n_takes=len(checked), n_cuts=int(sum(len(c) for _, c in checked)),
                    threshold=p["threshold"], prominence=prominence,
                    min_segment_s=p["min_segment_s"], scale_min_s=windows[0],
                    scale_max_s=windows[1], placement=placement, offset_s=offset)


def _as_example(item) -> Example:
    if isinstance(item, Example):
        return item
    take, cuts = item
    return Example(name=_where(take), cuts=cuts, fps=float(take.fps), n_frames=take.n_frames,
                   read=lambda: take)


def _label(windows) -> str:
    """A study's array-name prefix for the peaks of ``windows`` ("placed": zero-shot)."""
    return windows if isinstance(windows, str) else f"windows_{windows[0]:g}_{windows[1]:g}"


def _study_key(cuts: np.ndarray, p: dict, options) -> str:
    """What a study depends on besides its take: the cuts, the settings, the windows."""
    text = json.dumps([STUDY_VERSION, cuts.tolist(), sorted(p.items()),
                       [list(w) for w in options]])
    return hashlib.sha256(text.encode()).hexdigest()


def _study_names(options) -> set[str]:
    """The arrays a complete study holds."""
    return {f"residual_{name}" for name in PLACEMENTS} | {
        f"{_label(w)}_{part}" for w in ["placed", *options[1:]]
        for part in ("frames", "prominence", "raw")}


def _study(example: Example, cuts: np.ndarray, p: dict, options, studies) -> dict:
    """What one example teaches, as arrays: each placement step's residuals and the
    novelty peaks at the zero-shot and other ``options`` windows. From ``studies`` when
    stored there for these cuts and settings, else computed (and stored)."""
    keep = studies is not None and example.key is not None
    key = _study_key(cuts, p, options) if keep else ""
    if keep:
        stored = studies.load(example.key, key)
        if stored is not None and _study_names(options) <= set(stored):
            return stored
    take = segmenter_input(example.read(), Default.name)  # bare points: their coordinates
    analysis = default.analyse(take, p)
    if analysis is None:
        raise ExampleError(f"{example.name}: too short to learn from "
                           f"({example.n_frames} frames)")
    study, placed, found = _residuals(cuts, analysis, p)
    study.update(_all_peaks("placed", analysis, found, p, placed))
    others = analysis.with_windows(*options[1:]) if len(options) > 1 else []
    for windows, other in zip(options[1:], others, strict=True):
        window_p = {**p, "scale_min_s": windows[0], "scale_max_s": windows[1]}
        study.update(_all_peaks(_label(windows), other, default.peaks(other, window_p),
                                window_p, {}))
    if keep:
        studies.save(example.key, key, study)
    return study


def _window_options(zero_windows: tuple[float, float],
                    shortest: float | None) -> list[tuple[float, float]]:
    """The novelty windows to score, zero-shot first.

    Shorter windows are tried only when an example activity is shorter than the shortest
    zero-shot window: otherwise they only add cuts inside activities.
    """
    if shortest is None or shortest >= zero_windows[0]:
        return [zero_windows]
    return [zero_windows, *[w for w in WINDOW_OPTIONS if w != zero_windows]]


def _shortest_segment(checked) -> float | None:
    """The shortest inner human segment (s) over the examples; None without one."""
    shortest = [np.diff(cuts).min() / take.fps for take, cuts in checked if len(cuts) > 1]
    return min(shortest) if shortest else None


# The prominences (MMD², see segmenters.default) the count is chosen from, and the summed
# example fit that moving a factor e from the zero-shot prominence must buy: a prior that
# keeps one or two examples from pulling the count to wherever they happen to score best
# (in the units of ``_fit_by_prominence``: one edit per human cut of an average example
# is 1).
PROMINENCE_GRID = tuple(sorted({*np.round(np.geomspace(0.02, 2.0, 41), 4),
                                Default.params["prominence"].default}))
PROMINENCE_PRIOR = 0.05
# From this many example takes on, the prior's strength is itself chosen among
# PRIOR_OPTIONS (inf: keep the zero-shot prominence) by leave-one-example-take-out: the
# strength whose count, chosen on the other examples, fits the example left out best.
PRIOR_OPTIONS = (0.02, 0.05, 0.1, 0.2, 0.5, 1.0, math.inf)
PRIOR_CV_TAKES = 3
# Shorter novelty windows (s) the examples may choose when they hold activities shorter
# than the zero-shot shortest window, and the summed example fit such a choice must buy.
WINDOW_OPTIONS = ((2.0, 4.0), (1.5, 3.0))
WINDOW_PRIOR = 0.1


def matched_count(candidates: np.ndarray, truth: np.ndarray, tolerance: int) -> int:
    """Size of the largest one-to-one matching within ``tolerance`` frames.

    On a line with one tolerance for all, matching each true cut in order to the earliest
    free candidate in reach is optimal, and much faster than the assignment solver.
    """
    matched, j = 0, 0
    for t in truth:
        while j < len(candidates) and candidates[j] < t - tolerance:
            j += 1
        if j < len(candidates) and candidates[j] <= t + tolerance:
            matched += 1
            j += 1
    return matched


def _all_peaks(label: str, analysis, found: Peaks, p: dict,
               placed: dict) -> dict[str, np.ndarray]:
    """Every novelty peak of one example, as study arrays ``<label>_frames``,
    ``_prominence`` and ``_raw`` (the peak's own frame), in frame order.

    A peak the zero-shot detector keeps is counted where it places it (``placed``: peak
    index -> take frame), since its placement can move it by more than the tolerance
    (the onset after a pause); any other peak at its own frame. A kept peak that the
    detector replaces by the two sides of a short activity (``found.sides``, the
    zero-shot peaks) is counted as those two, each with its prominence, wherever the
    detector places them.
    """
    peaks, prominence = default.candidates(analysis, found, p)
    sides = found.sides
    index, of = [], []  # novelty sample counted, and the peak whose prominence it has
    for i, k in enumerate(peaks.tolist()):
        for counted in sides.get(k, (k,)):
            if counted != k and placed and counted not in placed:
                continue  # a side the detector drops (closer than min_segment_s to a cut)
            index.append(counted)
            of.append(i)
    raw = analysis.peak_frames(index) + analysis.first
    frames = np.asarray([placed.get(k, f) for k, f in zip(index, raw.tolist(), strict=True)],
                        dtype=np.int64)
    prominence = prominence[np.asarray(of, dtype=np.int64)]
    order = np.argsort(frames, kind="stable")
    return {f"{label}_frames": frames[order], f"{label}_prominence": prominence[order],
            f"{label}_raw": raw[order]}


def _unplaced(take_peaks: tuple) -> tuple:
    """``_all_peaks`` output with every peak back at its own frame (raw_frames order)."""
    _, prominence, cuts, tol, raw = take_peaks
    order = np.argsort(raw, kind="stable")
    return raw[order], prominence[order], cuts, tol, raw[order]


def _count(per_take, zero: float) -> tuple[float, float]:
    """The prominence of PROMINENCE_GRID whose peaks fit the example cuts best.

    The summed example fit (``_fit_by_prominence``) at each prominence, less the prior
    (``_prior_strength``) times how far (log factor) it lies from ``zero``, the zero-shot
    prominence. A zero-shot without the prominence test (0) counts as the grid's lowest
    prominence, the nearest test to none.

    Returns (score, prominence): the best score and its prominence.
    """
    fit = _fit_by_prominence(per_take)
    away = np.abs(np.log(np.asarray(PROMINENCE_GRID) / max(zero, PROMINENCE_GRID[0])))
    score = fit.sum(axis=0) - _penalty(away, _prior_strength(fit, away))
    best = _first_best(score)
    return float(score[best]), float(PROMINENCE_GRID[best])


def _fit_by_prominence(per_take) -> np.ndarray:
    """(n_takes, len(PROMINENCE_GRID)) how well each example's peaks kept at each
    prominence fit its human cuts: (human cuts - deletes - inserts) per human cut of an
    average example, the review edits the count decides (a peak matching no cut within
    1 s is a delete, a cut matching no peak an insert). Every edit weighs the same,
    whichever example it is in, so an example with few or no cuts (a take of one
    activity) does not outweigh the others."""
    per_cut = 1 / max(float(np.mean([len(t[2]) for t in per_take])), 1.0)
    out = np.empty((len(per_take), len(PROMINENCE_GRID)))
    for i, (frames, prom, cuts, tol, _) in enumerate(per_take):
        for j, prominence in enumerate(PROMINENCE_GRID):
            kept = frames[prom >= prominence]
            unmatched = len(kept) + len(cuts) - 2 * matched_count(kept, cuts, tol)
            out[i, j] = (len(cuts) - unmatched) * per_cut
    return out


def _penalty(away: np.ndarray, strength: float) -> np.ndarray:
    """The prior's cost at each prominence (0 at the zero-shot one, whatever the strength)."""
    out = np.zeros_like(away)
    out[away > 0] = strength * away[away > 0]
    return out


def _first_best(score: np.ndarray) -> int:
    """Index of the best score; ties (within 1e-9) go to the lowest prominence."""
    return int(np.flatnonzero(score >= score.max() - 1e-9)[0])


def _prior_strength(fit: np.ndarray, away: np.ndarray) -> float:
    """How strongly the count holds to the zero-shot prominence.

    With fewer than ``PRIOR_CV_TAKES`` examples, ``PROMINENCE_PRIOR``. With more, the
    option of ``PRIOR_OPTIONS`` that predicts each example best from the others: for
    each example, the count is chosen on the other examples with that strength and
    scored (``_fit_by_prominence``) on the one left out; the summed held-out fit
    decides, ties going to the stronger prior. Examples that agree with each other move
    the count; one example that alone wants a different count (a take with unusual
    activities) no longer can.
    """
    if len(fit) < PRIOR_CV_TAKES:
        return PROMINENCE_PRIOR
    total = fit.sum(axis=0)
    best, best_held = PROMINENCE_PRIOR, -math.inf
    for strength in PRIOR_OPTIONS:
        penalty = _penalty(away, strength)
        held = sum(fit[i, _first_best(total - fit[i] - penalty)] for i in range(len(fit)))
        if held >= best_held - 1e-9:
            best, best_held = strength, held
    return best


def _residuals(cuts: np.ndarray, analysis, p: dict) -> tuple[dict, dict[int, int], Peaks]:
    """Each placement step's signed (human - placed) offsets in seconds over the
    zero-shot cuts that match a human cut within 1 s, as study arrays
    ``residual_<step>``.

    Returns
    -------
    the arrays; novelty peak index -> take frame where the zero-shot detector places
    that peak; and the zero-shot peaks.
    """
    found = default.peaks(analysis, p)
    placement = default.place(analysis, found, p)
    arrays = {}
    for name, placed in placement.stages.items():
        placed = placed + analysis.first
        ci, ti = metrics.match(placed, cuts, tolerance=int(round(MATCH_S * analysis.fps)))
        arrays[f"residual_{name}"] = (cuts[ti] - placed[ci]) / analysis.fps
    zero_shot = placement.cuts + analysis.first
    return arrays, dict(zip(found.samples.tolist(), zero_shot.tolist(), strict=True)), found


def _placement(residuals: dict, zero_shot: str) -> tuple[str, float]:
    """The placement step and shift (s) that follow the human cuts best, if clearly so."""
    r = np.asarray(residuals[zero_shot])
    if len(r) < PLACEMENT_MIN_CUTS:
        return zero_shot, 0.0
    base = float(np.median(np.abs(r)))
    best, best_error = (zero_shot, 0.0), base
    for name in PLACEMENTS:
        r = np.asarray(residuals[name])
        offset = float(np.median(r))
        error = float(np.median(np.abs(r - offset)))
        if error < best_error:
            best, best_error = (name, offset), error
    ratio, seconds = PLACEMENT_GAIN
    if best_error > min((1 - ratio) * base, base - seconds):
        return zero_shot, 0.0
    return best


def _segment(analysis, p: dict, placement: str, offset_s: float) -> Segmentation:
    found = default.peaks(analysis, p)
    placed = default.place(analysis, found, p)
    cuts = placed.stages[placement] + int(round(offset_s * analysis.fps))
    result = analysis.segmentation(cuts, found.confidence(p), placed.speed)
    return result.checked(len(analysis.x) + analysis.first)


def detect_threshold(take, model: ThresholdModel | None = None, **params) -> Segmentation:
    """Candidate cuts of ``take``; ``model=None`` is the zero-shot default detector.

    ``params`` are the ``default`` segmenter's parameters (validated with its schema);
    with a model, its learnt ``threshold``, ``prominence``, ``min_segment_s`` and windows
    (``scale_min_s``, ``scale_max_s``) replace those, and each cut is taken from its
    ``placement`` step and moved by its ``offset_s``.

    Returns
    -------
    Segmentation, as ``Default(**params).fit_predict(take)``.
    """
    if model is None:
        return Default(**params).fit_predict(take)
    p = {**Default.validate_params(params), **model.params()}
    start = time.perf_counter()
    take = segmenter_input(take, Default.name)  # bare points: their coordinates
    analysis = default.analyse(take, p)
    if analysis is None:  # too short to compare anything: no cuts, as the detector says
        result = Segmentation(np.zeros(0, np.int64), np.zeros(0),
                              {"novelty": np.zeros(take.n_frames)})
    else:
        result = _segment(analysis, p, model.placement, model.offset_s)
    result.timings["total"] = time.perf_counter() - start
    return result
