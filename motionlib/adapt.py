"""Adapting the default detector to a studio's own cuts.

A studio's annotators have a convention: what counts as a boundary, how many there are,
where exactly the cut goes. Given example takes with their human cuts,
:func:`fit_cut_model` learns that convention as a :class:`CutModel`, and :func:`detect`
runs the default detector with it.

What is learnt, step by step (each from all examples together, never per take):

1. *Minimum segment and windows.* The shortest human segment bounds how close two cuts
   may be: ``min_segment_s`` is 0.75 x the shortest example segment, within [0.5, 4] s;
   and the novelty windows must fit into it to see it: the shortest window is the shortest
   segment (at most the zero-shot 3 s, at least 1 s), the longest twice that.
2. *How many cuts.* The novelty threshold that scores the best F1 at 1 s between the
   novelty peaks and the human cuts, summed over the examples (ties: the threshold nearest
   the zero-shot default).
3. *Where.* Each placement step of the detector (best split, turning point, pause; see
   ``segmenters.default``) is an anchor; for each, the signed offsets from the detected
   cut to the human cut it matches within 1 s. The anchor whose offsets vary least (median
   absolute deviation) is kept with their median as a shift: annotators who mark the onset
   of the next activity cut a steady time after the statistical change.

Pure numpy/scipy, no Django; the service stores ``CutModel.to_json()``.
"""

from __future__ import annotations

import csv
import json
import math
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from motionlib import metrics
from motionlib.segmenters.base import Segmentation, _checked
from motionlib.segmenters.default import PLACEMENTS, Default, empty_segmentation, place_stages

FORMAT = 1
MIN_SEGMENT_RANGE_S = (0.5, 4.0)
MIN_SEGMENT_FACTOR = 0.75
MATCH_S = 1.0


class ExampleError(ValueError):
    """An example take or its cuts cannot be learnt from; the message names it."""


@dataclass(frozen=True)
class CutModel:
    """What the default detector learnt from example takes with human cuts.

    n_takes : example takes it learnt from.
    n_cuts : human cuts it learnt from.
    threshold : novelty peak height (mean MMD²) for a cut.
    min_segment_s : minimum time between two cuts (s).
    scale_min_s, scale_max_s : shortest and longest novelty window (s).
    placement : the placement step the cut is taken from ("split", "turn" or "pause").
    offset_s : signed shift added to every placed cut (s); positive moves cuts later.
    """

    n_takes: int
    n_cuts: int
    threshold: float
    min_segment_s: float
    scale_min_s: float
    scale_max_s: float
    placement: str
    offset_s: float

    def params(self) -> dict[str, float]:
        """The default segmenter's parameters this model sets."""
        return {"threshold": self.threshold, "min_segment_s": self.min_segment_s,
                "scale_min_s": self.scale_min_s, "scale_max_s": self.scale_max_s}

    def to_json(self) -> str:
        """Stable JSON text (sorted keys) with ``"format": 1``."""
        return json.dumps({"format": FORMAT, **asdict(self)}, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> CutModel:
        """Parse ``to_json`` output; ValueError naming what is wrong."""
        try:
            data = json.loads(text)
        except (TypeError, json.JSONDecodeError) as exc:
            raise ValueError(f"cut model: not JSON: {exc}") from None
        if not isinstance(data, dict):
            raise ValueError(f"cut model: expected a JSON object, got {type(data).__name__}")
        if data.get("format") != FORMAT:
            raise ValueError(f"cut model: unsupported format {data.get('format')!r} "
                             f"(expected {FORMAT})")
        values = {}
        for name, kind in (("n_takes", int), ("n_cuts", int), ("threshold", float),
                           ("min_segment_s", float), ("scale_min_s", float),
                           ("scale_max_s", float), ("offset_s", float)):
            value = data.get(name)
            ok = isinstance(value, int | float) and not isinstance(value, bool)
            if not ok or not math.isfinite(value) or (kind is int and value != int(value)):
                raise ValueError(f"cut model: {name} must be a finite "
                                 f"{'integer' if kind is int else 'number'}, got {value!r}")
            values[name] = kind(value)
        if data.get("placement") not in PLACEMENTS:
            raise ValueError(f"cut model: placement must be one of {', '.join(PLACEMENTS)}, "
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


def fit_cut_model(examples: Sequence[tuple[object, Sequence[int]]]) -> CutModel:
    """Adapt the default detector to example takes with human cuts.

    Parameters
    ----------
    examples : sequence of (take, cuts); cuts are 0-based take frames where a new segment
        starts (a take with no cut is a valid example: one activity throughout).

    Raises
    ------
    ExampleError (a ValueError) naming the take and the value: an empty example list, a cut
    outside the take, a take too short to analyse.
    """
    if len(examples) == 0:
        raise ExampleError("no example takes to learn from")
    p = Default.validate_params({})
    prepared = []
    for take, cuts in examples:
        cuts = _checked_cuts(take, cuts)
        analysis = Default.analyse(take, p)
        if analysis is None:
            raise ExampleError(f"{_where(take)}: too short to learn from "
                               f"({take.n_frames} frames)")
        prepared.append((take, cuts, analysis))
    shortest = _shortest_segment(prepared)
    if shortest is not None:
        lo, hi = MIN_SEGMENT_RANGE_S
        scale = float(np.clip(shortest, 1.0, p["scale_min_s"]))
        p = {**p, "min_segment_s": float(np.clip(MIN_SEGMENT_FACTOR * shortest, lo, hi)),
             "scale_min_s": scale, "scale_max_s": 2 * scale}
        if scale != Default.params["scale_min_s"].default:
            prepared = [(take, cuts, Default.analyse(take, p)) for take, cuts, _ in prepared]
    threshold = _threshold(prepared, p)
    p = {**p, "threshold": threshold}
    placement, offset = _placement(prepared, p)
    return CutModel(n_takes=len(prepared), n_cuts=int(sum(len(c) for _, c, _ in prepared)),
                    threshold=threshold, min_segment_s=p["min_segment_s"],
                    scale_min_s=p["scale_min_s"], scale_max_s=p["scale_max_s"],
                    placement=placement,
                    offset_s=offset)


def _shortest_segment(prepared) -> float | None:
    """The shortest inner human segment (s) over the examples; None without one."""
    shortest = [np.diff(cuts).min() / take.fps for take, cuts, _ in prepared if len(cuts) > 1]
    return min(shortest) if shortest else None


def _threshold(prepared, p: dict) -> float:
    """The novelty threshold with the best summed F1@1 s of raw peaks over the examples."""
    candidates = []
    per_take = []
    for take, cuts, analysis in prepared:
        peaks, strength = Default._peaks(analysis.novelty, analysis.rate,
                                         {**p, "threshold": 1e-9})
        frames = analysis.peak_frames(peaks) + analysis.first
        per_take.append((take, cuts, frames, strength))
        candidates.extend(strength.tolist())
    # Thresholds just below each observed peak height, plus the default.
    grid = np.unique(np.concatenate([np.asarray(candidates) * (1 - 1e-6), [p["threshold"]]]))
    best, best_key = p["threshold"], None
    for threshold in grid:
        score = 0.0
        for take, cuts, frames, strength in per_take:
            kept = frames[strength >= threshold]
            score += metrics.boundary_scores(kept, cuts, fps=take.fps, tolerance_s=MATCH_S)["f1"]
        key = (round(score, 9), -abs(math.log(threshold / p["threshold"])))
        if best_key is None or key > best_key:
            best, best_key = float(threshold), key
    return best


def _placement(prepared, p: dict) -> tuple[str, float]:
    """The placement step and shift (s) that follow the human cuts most steadily."""
    residuals = {name: [] for name in PLACEMENTS}
    for take, cuts, analysis in prepared:
        peaks, _ = Default._peaks(analysis.novelty, analysis.rate, p)
        stages, _ = place_stages(analysis.x, analysis.peak_frames(peaks), analysis.fps,
                                 analysis.gamma, p)
        for name, placed in stages.items():
            placed = placed + analysis.first
            ci, ti = metrics.match(placed, cuts, tolerance=int(round(MATCH_S * take.fps)))
            residuals[name].extend(((cuts[ti] - placed[ci]) / take.fps).tolist())
    best = ("pause", 0.0)
    best_spread = math.inf
    for name in ("pause", "turn", "split"):  # ties keep the zero-shot step
        r = np.asarray(residuals[name])
        if len(r) == 0:
            continue
        offset = float(np.median(r))
        spread = float(np.median(np.abs(r - offset)))
        if spread < best_spread - 1e-9:
            best, best_spread = (name, offset), spread
    return best


def _segment(analysis, p: dict, placement: str = "pause", offset_s: float = 0.0) -> Segmentation:
    peaks, strength = Default._peaks(analysis.novelty, analysis.rate, p)
    stages, speed = place_stages(analysis.x, analysis.peak_frames(peaks), analysis.fps,
                                 analysis.gamma, p)
    cuts = stages[placement] + int(round(offset_s * analysis.fps))
    result = analysis.segmentation(cuts, strength / (strength + p["threshold"] + 1e-12), speed)
    return _checked(result, len(analysis.x) + analysis.first)


def detect(take, model: CutModel | None = None, **params) -> Segmentation:
    """Candidate cuts of ``take``; ``model=None`` is the zero-shot default detector.

    ``params`` are the ``default`` segmenter's parameters (validated with its schema);
    with a model, its learnt ``threshold`` and ``min_segment_s`` replace those two, and
    each cut is taken from its ``placement`` step and moved by its ``offset_s``.

    Returns
    -------
    Segmentation, as ``Default(**params).fit_predict(take)``.
    """
    if model is None:
        return Default(**params).fit_predict(take)
    p = {**Default.validate_params(params), **model.params()}
    analysis = Default.analyse(take, p)
    if analysis is None:
        return empty_segmentation(take)
    return _segment(analysis, p, model.placement, model.offset_s)


# --- examples CSV -----------------------------------------------------------------------

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
        with open(path, newline="", encoding="utf-8") as fh:
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
