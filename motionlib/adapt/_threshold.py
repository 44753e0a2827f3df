"""The first format of a studio's cut model (format 1), kept so that models stored in it
load and detect exactly as they did; ``motionlib.adapt`` learns format 2 now, and
nothing learns this format any more.

A :class:`ThresholdModel` is the default detector's own settings adapted to a studio's
example takes: a novelty ``threshold`` and ``prominence`` for a cut, the shortest segment,
the novelty windows, and the placement step and shift cuts are taken from.
:func:`detect_threshold` runs the detector with them, through its public steps
(``segmenters.default``: ``analyse``, ``peaks``, ``place``). How those settings were learnt
is recorded in ``docs/detector/adaptation.md``.

Pure numpy/scipy, no Django; a stored ``ThresholdModel.to_json()`` loads with
``CutModel.from_json`` as with :meth:`ThresholdModel.from_json`.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from motionlib.errors import InputError
from motionlib.points import segmenter_input
from motionlib.segmenters import default
from motionlib.segmenters.base import Segmentation
from motionlib.segmenters.default import PLACEMENTS, Default

FORMAT = 1
# Fields added to format 1 after its first models were stored, with the value that keeps
# those models detecting as they did (no prominence test).
OPTIONAL_FIELDS = {"prominence": 0.0}


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
