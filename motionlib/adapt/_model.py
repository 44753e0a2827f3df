"""A studio's cut model (format 2) and how it cuts a take: a scorer over the take's
candidates (``_candidates``).

A :class:`CutModel` keeps a candidate when a logistic scorer over its evidence
(``_evidence``) says it is more likely a human cut than not (a reviewer gains from a
candidate only then: a false one costs a delete, a missing one an insert), keeps no two
kept candidates closer than its ``min_segment_s`` (the convention's fineness), and cuts
each at its ``placement`` step moved by ``offset_s`` (:func:`select`). With the prior's
weights (:meth:`CutModel.zero_shot`) it keeps exactly the zero-shot cuts. How a model
is learnt is ``_learner``; a stored model of any format is read by
:meth:`CutModel.from_json` (format 1: ``_threshold``).
"""

from __future__ import annotations

import bisect
import json
import math
from dataclasses import dataclass

import numpy as np
from scipy.special import expit

from motionlib.adapt._evidence import CENTRES, FEATURES
from motionlib.adapt._threshold import ThresholdModel
from motionlib.errors import InputError
from motionlib.segmenters.default import PLACEMENTS, shipped_stage

FORMAT = 2
# The zero-shot decision as a scorer: a zero-shot cut has odds e^3 of being kept, any
# other candidate e^-3; nothing else counts.
PRIOR_INTERCEPT = -3.0
PRIOR_ZERO_SHOT = 6.0

@dataclass(frozen=True)
class CutModel:
    """A studio's convention over the default detector's candidates (format 2).

    n_takes, n_cuts : example takes and human cuts it learnt from (0: zero-shot).
    weights : one per ``features`` plus the intercept last: the logistic scorer over the
        centred evidence features.
    features : names of the features the weights are for (``_evidence.FEATURES``).
    min_segment_s : no two kept candidates lie closer (s); the more probable one stays.
    placement : the placement step cuts are taken from (``PLACEMENTS``).
    offset_s : signed shift (s) added to every cut; positive moves cuts later.
    tolerance_s : how far (s) a candidate may lie from a human cut to count as it.
    down_weighted : example takes weighted down as disagreeing with the others.
    precision : the prior precision the scorer was fitted with (inf: the zero-shot one).
    threshold : the scorer's logit a candidate must exceed: 0 keeps those more likely
        true than not; another value makes the typical example take's count right.
    """

    n_takes: int
    n_cuts: int
    weights: tuple[float, ...]
    features: tuple[str, ...]
    min_segment_s: float
    placement: str
    offset_s: float
    tolerance_s: float
    down_weighted: int = 0
    precision: float = math.inf
    threshold: float = 0.0

    @classmethod
    def zero_shot(cls, tolerance_s: float = 1.0) -> CutModel:
        """The prior: detects exactly what the zero-shot detector does (it keeps only the
        zero-shot cuts, spaced as the detector spaces them: ``min_segment_s`` 0)."""
        return cls(n_takes=0, n_cuts=0, weights=tuple(prior_weights().tolist()), features=FEATURES,
                   min_segment_s=0.0, placement=shipped_stage({"onset": True}),
                   offset_s=0.0, tolerance_s=tolerance_s)

    def to_json(self) -> str:
        """Stable JSON text (sorted keys) with ``"format": 2``."""
        data = {"format": FORMAT, "n_takes": self.n_takes, "n_cuts": self.n_cuts,
                "weights": list(self.weights), "features": list(self.features),
                "min_segment_s": self.min_segment_s, "placement": self.placement,
                "offset_s": self.offset_s, "tolerance_s": self.tolerance_s,
                "down_weighted": self.down_weighted,
                "precision": self.precision if math.isfinite(self.precision) else None,
                "threshold": self.threshold}
        return json.dumps(data, sort_keys=True)

    @classmethod
    def from_json(cls, text: str):
        """Parse a stored model of any format: a :class:`CutModel` (format 2) or a
        ``ThresholdModel`` (format 1, detecting as it always did); InputError (a
        ValueError) naming what is wrong."""
        try:
            data = json.loads(text)
        except (TypeError, json.JSONDecodeError) as exc:
            raise InputError(f"cut model: not JSON: {exc}") from None
        if not isinstance(data, dict):
            raise InputError(f"cut model: expected a JSON object, got {type(data).__name__}")
        if data.get("format") == 1:
            return ThresholdModel.from_json(text)
        if data.get("format") != FORMAT:
            raise InputError(f"cut model: unsupported format {data.get('format')!r} "
                             f"(expected 1 or {FORMAT})")

        def fault(message):
            raise InputError(f"cut model: {message}")
        return cls.from_dict(data, fault)

    @classmethod
    def from_dict(cls, data: dict, fault) -> CutModel:
        """A format-2 model from parsed JSON; ``fault(message)`` raises for bad values."""
        if data.get("features") != list(FEATURES):
            fault(f"features must be {list(FEATURES)}, got {data.get('features')!r}")
        weights = data.get("weights")
        if not isinstance(weights, list) or len(weights) != len(FEATURES) + 1 or not all(
                _finite(w) for w in weights):
            fault(f"weights must be {len(FEATURES) + 1} finite numbers, got {weights!r}")
        values = {}
        for name, kind in (("n_takes", int), ("n_cuts", int), ("down_weighted", int),
                           ("min_segment_s", float), ("offset_s", float),
                           ("tolerance_s", float), ("threshold", float)):
            value = data.get(name)
            if not _finite(value) or (kind is int and value != int(value)):
                fault(f"{name} must be a finite {'integer' if kind is int else 'number'}, "
                      f"got {value!r}")
            values[name] = kind(value)
        if data.get("placement") not in PLACEMENTS:
            fault(f"placement must be one of {', '.join(PLACEMENTS)}, "
                  f"got {data.get('placement')!r}")
        precision = data.get("precision")
        if precision is not None and not (_finite(precision) and precision > 0):
            fault(f"precision must be a positive number or null, got {precision!r}")
        return cls(**values, weights=tuple(float(w) for w in weights), features=FEATURES,
                   placement=data["placement"],
                   precision=math.inf if precision is None else float(precision))



def _finite(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and \
        math.isfinite(value)



def prior_weights() -> np.ndarray:
    """(len(FEATURES) + 1,) the prior's weights, the intercept last: the zero-shot
    decision (PRIOR_ZERO_SHOT on ``zero_shot``, PRIOR_INTERCEPT), 0 on all other evidence."""
    w = np.zeros(len(FEATURES) + 1)
    w[FEATURES.index("zero_shot")] = PRIOR_ZERO_SHOT
    w[-1] = PRIOR_INTERCEPT
    return w


def design(features: np.ndarray) -> np.ndarray:
    """(n, len(FEATURES) + 1) the centred features and a column of ones."""
    return np.hstack([features - CENTRES, np.ones((len(features), 1))])


def scorer_inputs(model: CutModel, one: dict) -> np.ndarray:
    """(n, len(model.features) + 1) what ``model``'s scorer reads of a study's candidates:
    their evidence (the study's ``features``), centred, and a column of ones. Fitting and
    selecting both read the candidates through here, so evidence a study does not keep
    (from a model of the project's other takes, which ``model`` would then carry) joins
    the scorer in one place."""
    return design(one["features"])



def select(model: CutModel, one: dict) -> tuple[np.ndarray, np.ndarray]:
    """The cuts ``model`` keeps among a study's candidates: (frames, probability),
    in frame order. Most probable first, a candidate is kept when its scorer's logit
    exceeds the model's ``threshold`` and no kept cut lies within ``min_segment_s``."""
    logits, order, frames, kept = ranked(model, one)
    chosen = order[kept & (logits > model.threshold)]
    chosen = chosen[np.argsort(frames[chosen], kind="stable")]
    return frames[chosen], expit(logits[np.argsort(order)][chosen])


def ranked(model: CutModel, one: dict):
    """(logits, order, frames, kept): the candidates' logits from the most probable down,
    their indices, every candidate's frame (``placed``), and which of the ranked
    candidates ``select`` keeps at a threshold below all of them. A candidate's fate
    depends only on those ranked before it, so at any threshold ``select`` keeps exactly
    the kept ones above it: one pass serves every threshold (``_learner``)."""
    logit = scorer_inputs(model, one) @ np.asarray(model.weights)
    frames = placed(model, one)
    gap = int(round(model.min_segment_s * float(one["fps"])))
    order = np.argsort(-logit, kind="stable")
    kept = np.zeros(len(order), dtype=bool)
    taken: list[int] = []  # kept frames, sorted
    for rank, i in enumerate(order.tolist()):
        f = int(frames[i])
        at = bisect.bisect_left(taken, f)
        if (at < len(taken) and taken[at] - f < gap) or (at and f - taken[at - 1] < gap):
            continue
        taken.insert(at, f)
        kept[rank] = True
    return logit[order], order, frames, kept


def placed(model: CutModel, one: dict) -> np.ndarray:
    """(n,) every candidate's frame at the model's placement step and offset."""
    fps, n = float(one["fps"]), int(one["n_frames"])
    frames = one["stages"][:, PLACEMENTS.index(model.placement)] + \
        int(round(model.offset_s * fps))
    return np.clip(frames, 1, max(1, n - 1))
