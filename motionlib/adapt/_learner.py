"""A studio's cutting convention learnt as a scorer over over-complete candidates.

Every take is described by many candidate cuts with a few evidence features each
(``_candidates``). A :class:`CutModel` keeps a candidate when a logistic scorer over
those features says it is more likely a human cut than not (a reviewer gains from a
candidate only then: a false one costs a delete, a missing one an insert), keeps no two
kept candidates closer than its ``min_segment_s`` (the convention's fineness), and cuts
each at its ``placement`` step moved by ``offset_s``.

The scorer is a maximum-a-posteriori logistic regression whose Gaussian prior is centred
on the zero-shot decision (keep exactly the zero-shot cuts): with no example it *is* the
zero-shot detector, a few examples move it a little, many move it as far as they agree.
Takes are weighted before the final fit: each is predicted by a model fitted on the
others, and one that disagrees far more than the rest (a reviewer who cut half the
cuts, or twice as many) is down-weighted, so that a minority of bad reviews cannot
drag the model. Fineness and placement are medians over takes for the same reason.
How the fixed settings were chosen is in ``docs/detector/adaptation.md``.
"""

from __future__ import annotations

import bisect
import hashlib
import json
import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.special import expit

from motionlib import metrics
from motionlib.adapt._candidates import FEATURES, study_take
from motionlib.errors import InputError
from motionlib.segmenters.default import PLACEMENTS, shipped_stage

FORMAT = 2
# Fixed centres of the features (typical values), so that the intercept means "a typical
# candidate" and the prior on it is not dodged through a feature's offset.
CENTRES = np.array([0.0, -2.3, -2.3, -1.0, -2.3, 0.0, 0.0, 1.0, 0.0])
# The zero-shot decision as a scorer: a zero-shot cut has odds e^3 of being kept, any
# other candidate e^-3; nothing else counts.
PRIOR_INTERCEPT = -3.0
PRIOR_ZERO_SHOT = 6.0
# Prior precision on every weight, in units of one candidate's worth of evidence: fixed
# (strong: a take or two move the scorer little) below CV_TAKES examples; from there on
# chosen among PRECISIONS (inf: the zero-shot scorer itself) by cross-validation over
# the example takes (CV_FOLDS folds at most), held-out F1 deciding, ties to the stronger
# prior. Examples that agree with each other move the scorer; a lucky fit does not.
FIXED_PRECISION = 100.0
PRECISIONS = (math.inf, 100.0, 10.0, 1.0)
CV_TAKES = 3
CV_FOLDS = 3
# The count calibration's search: logit thresholds within +-CALIBRATION_RANGE, halved
# this many times.
CALIBRATION_RANGE = 8.0
CALIBRATION_STEPS = 8
# The precision the take weighting's held-out fits use.
WEIGHTING_PRECISION = 10.0
# Take weighting: a take whose held-out loss lies more than this many robust standard
# deviations above the others' median is weighted down as (limit / z)².
OUTLIER_Z = 2.5
COUNT_SPREAD = 0.15
# Fineness: the shortest segment an example shows, times this, bounds how close two kept
# candidates may lie, within [MIN_SEGMENT_S, MAX_SEGMENT_S].
MIN_SEGMENT_FACTOR = 0.75
MIN_SEGMENT_S = 0.3
MAX_SEGMENT_S = 8.0
# A placement other than the zero-shot one needs this many matched example cuts and must
# cut the median placement error by this fraction and this many seconds.
PLACEMENT_MIN_CUTS = 6
PLACEMENT_MIN_TAKES = 2
PLACEMENT_GAIN = (0.2, 0.03)
STUDY_VERSION = 1


@dataclass(frozen=True)
class CutModel:
    """A studio's convention over the default detector's candidates (format 2).

    n_takes, n_cuts : example takes and human cuts it learnt from (0: zero-shot).
    weights : one per ``features`` plus the intercept last: the logistic scorer over the
        centred evidence features.
    features : names of the features the weights are for (``_candidates.FEATURES``).
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
        return cls(n_takes=0, n_cuts=0, weights=tuple(_prior().tolist()), features=FEATURES,
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
        from motionlib.adapt._threshold import ThresholdModel

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


def _prior() -> np.ndarray:
    w = np.zeros(len(FEATURES) + 1)
    w[FEATURES.index("zero_shot")] = PRIOR_ZERO_SHOT
    w[-1] = PRIOR_INTERCEPT
    return w


def design(features: np.ndarray) -> np.ndarray:
    """(n, len(FEATURES) + 1) the centred features and a column of ones."""
    return np.hstack([features - CENTRES, np.ones((len(features), 1))])


def study_key(p: dict) -> str:
    """What a take's study depends on besides the take: the detector settings."""
    text = json.dumps([STUDY_VERSION, sorted(p.items())])
    return hashlib.sha256(text.encode()).hexdigest()


def study(take, p: dict) -> dict[str, np.ndarray] | None:
    """A take's candidates (``_candidates.study_take``)."""
    return study_take(take, p)


# ---- detection from a study ----------------------------------------------------------------

def select(model: CutModel, one: dict) -> tuple[np.ndarray, np.ndarray]:
    """The cuts ``model`` keeps among a study's candidates: (frames, probability),
    in frame order. Most probable first, a candidate is kept when its scorer's logit
    exceeds the model's ``threshold`` and no kept cut lies within ``min_segment_s``."""
    logits, order, frames, kept = _ranked(model, one)
    chosen = order[kept & (logits > model.threshold)]
    chosen = chosen[np.argsort(frames[chosen], kind="stable")]
    return frames[chosen], expit(logits[np.argsort(order)][chosen])


def _ranked(model: CutModel, one: dict):
    """(logits, order, frames, kept): the candidates' logits from the most probable down,
    their indices, every candidate's frame (``placed``), and which of the ranked
    candidates ``select`` keeps at a threshold below all of them. A candidate's fate
    depends only on those ranked before it, so at any threshold ``select`` keeps exactly
    the kept ones above it: one pass serves every threshold (``_calibrated``)."""
    logit = design(one["features"]) @ np.asarray(model.weights)
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


# ---- learning ------------------------------------------------------------------------------

def fit(studies: list[dict], cuts: list[np.ndarray], *, tolerance_s: float,
        zero_min_segment_s: float, choice: tuple | None = None):
    """Learn a :class:`CutModel` from example studies and their human cuts (take frames).

    Returns (model, choice). ``choice`` is what the fit chose from all its examples
    together: the examples' weights, the prior's precision and whether the count is
    calibrated. Given back (the weights of the examples kept, in order), a refit on fewer
    of the same examples takes it instead of choosing again: those choices are most of
    a fit's cost, and a refit without one example, as the gate's leave-one-out makes, is
    then a single regression. Below CV_TAKES examples a refit chooses anew (cheaply).
    """
    prior = CutModel.zero_shot(tolerance_s)
    placement, offset = _placement(studies, cuts, tolerance_s)
    fine = _min_segment([(c, float(s["fps"])) for c, s in zip(cuts, studies, strict=True)],
                        zero_min_segment_s)
    base = replace(prior, placement=placement, offset_s=offset, min_segment_s=fine)
    data = [_labelled(base, one, c) for one, c in zip(studies, cuts, strict=True)]
    if choice is None or len(studies) < CV_TAKES:
        weights = _take_weights(base, studies, cuts, data)
    else:
        weights = np.asarray(choice[0], dtype=float)
    if len(studies) < CV_TAKES:  # one or two takes do not show how finely a studio cuts
        base = replace(base, min_segment_s=0.0)
    if choice is None or len(studies) < CV_TAKES:
        precision, calibrate = _choose(base, studies, cuts, data, weights)
    else:
        precision, calibrate = choice[1], choice[2]
    model = replace(base, weights=tuple(float(v) for v in _map_fit(data, weights, precision)),
                    n_takes=len(studies), n_cuts=int(sum(len(c) for c in cuts)),
                    down_weighted=int(np.sum(weights < 0.5)), precision=precision)
    if calibrate:
        trusted = weights >= 0.5
        model = replace(model, threshold=_calibrated(
            model, [s for s, t in zip(studies, trusted, strict=True) if t],
            [c for c, t in zip(cuts, trusted, strict=True) if t]))
    return model, (weights, precision, calibrate)


def _calibrated(model: CutModel, studies, cuts) -> float:
    """The logit threshold at which the median example take keeps as many cuts as its
    reviewers made (bisection; more threshold, fewer cuts). A count set by the median
    take, so a minority of under- or over-cut takes moves it little."""
    ranked = []
    for one, c in zip(studies, cuts, strict=True):
        logits, _, _, kept = _ranked(model, one)
        ranked.append((-logits, np.concatenate([[0], np.cumsum(kept)]), len(c)))

    def excess(threshold):
        # The ranked candidates above the threshold are a prefix; count its kept ones.
        return float(np.median([
            math.log((kept[np.searchsorted(descending, -threshold, side="left")] + 1) /
                     (n_true + 1)) for descending, kept, n_true in ranked]))
    lo, hi = -CALIBRATION_RANGE, CALIBRATION_RANGE
    for _ in range(CALIBRATION_STEPS):
        mid = (lo + hi) / 2
        if excess(mid) > 0:
            lo = mid
        else:
            hi = mid
    return round((lo + hi) / 2, 4)


def _labelled(model: CutModel, one: dict, cuts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(design matrix, 0/1 labels): a candidate is a cut when, placed as ``model``
    places it, it is matched one-to-one to a human cut within the tolerance."""
    frames = placed(model, one)
    y = np.zeros(len(frames))
    ci, _ = metrics.match(frames, cuts, tolerance=int(round(model.tolerance_s *
                                                               float(one["fps"]))))
    y[ci] = 1.0
    return design(one["features"]), y


def _choose(base: CutModel, studies, cuts, data, weights) -> tuple[float, bool]:
    """(prior precision, calibrate the count): below CV_TAKES examples FIXED_PRECISION
    and no calibration (keep what is more likely true than not; ``_calibrated``
    otherwise); else the pair whose models, fitted without a fold of example takes, cut
    those takes with the best weighted mean F1 (at the model's tolerance), ties going
    to the stronger prior and to no calibration."""
    n = len(data)
    if n < CV_TAKES:
        return FIXED_PRECISION, False
    folds = min(n, CV_FOLDS)
    best, best_score = (math.inf, False), -math.inf
    for precision in PRECISIONS:
        scores = {False: 0.0, True: 0.0}
        for fold in range(folds):
            held = np.arange(n) % folds == fold
            weights_in = np.where(held, 0.0, weights)
            fitted = replace(base, weights=tuple(_map_fit(data, weights_in, precision)))
            trusted = [i for i in range(n) if not held[i] and weights[i] >= 0.5]
            calibrated = replace(fitted, threshold=_calibrated(
                fitted, [studies[i] for i in trusted], [cuts[i] for i in trusted]))
            for calibrate, m in ((False, fitted), (True, calibrated)):
                for i in np.flatnonzero(held).tolist():
                    found = select(m, studies[i])[0]
                    scores[calibrate] += weights[i] * metrics.boundary_scores(
                        found, cuts[i], fps=float(studies[i]["fps"]),
                        tolerance_s=base.tolerance_s)["f1"]
        for calibrate in (False, True):
            if scores[calibrate] > best_score + 1e-9:
                best, best_score = (precision, calibrate), scores[calibrate]
    return best


def _map_fit(data, take_weights: np.ndarray, precision: float,
             start: np.ndarray | None = None) -> np.ndarray:
    """MAP logistic regression: summed weighted log-loss plus the Gaussian prior of
    ``precision`` around the zero-shot scorer (Newton's method from ``start``, the prior
    by default; the objective is strictly convex, so every start reaches its one
    minimum). An infinite precision is the prior itself."""
    w0 = _prior()
    if not data or not math.isfinite(precision):
        return w0
    x = np.vstack([d[0] for d in data])
    y = np.concatenate([d[1] for d in data])
    sw = np.concatenate([np.full(len(d[1]), wt) for d, wt in zip(data, take_weights,
                                                                  strict=True)])
    def objective(w):
        z = x @ w
        return float(sw @ (np.logaddexp(0, z) - y * z)) + \
            precision / 2 * float((w - w0) @ (w - w0))

    w = (w0 if start is None else start).copy()
    eye = precision * np.eye(len(w))
    current = objective(w)
    for _ in range(50):
        p = expit(x @ w)
        grad = x.T @ (sw * (p - y)) + precision * (w - w0)
        hess = (x * (sw * p * (1 - p))[:, None]).T @ x + eye
        step = np.linalg.solve(hess, grad)
        # Damped: a full Newton step can overshoot where the log-loss is nearly flat.
        for _ in range(30):
            trial = objective(w - step)
            if trial <= current:
                break
            step = step / 2
        w, current = w - step, min(trial, current)
        if np.abs(step).max() < 1e-8:
            break
    return w


def _log_loss(w: np.ndarray, x: np.ndarray, y: np.ndarray) -> float:
    z = x @ w
    return float(np.mean(np.logaddexp(0, z) - y * z)) if len(y) else 0.0


def _take_weights(base: CutModel, studies, cuts, data) -> np.ndarray:
    """Each example's weight: 1, or less for a take that disagrees with a model fitted on
    the others, by either of two robust z-scores over the takes (``_down_weight``):

    - its held-out mean log-loss (candidates labelled unlike the others would);
    - the log ratio of its human cuts to the cuts that model keeps in it: the signature
      of a reviewer who cut half the cuts, or twice as many (deviations within
      ``COUNT_SPREAD`` are never outliers: takes differ that much by themselves).

    From three takes on; with fewer there is no majority to disagree with."""
    n = len(data)
    if n < 3:
        return np.ones(n)
    loss, ratio = np.empty(n), np.empty(n)
    # Leaving one take out moves the fit little: Newton starts from the fit on all.
    everyone = _map_fit(data, np.ones(n), WEIGHTING_PRECISION)
    for i in range(n):
        others = np.ones(n)
        others[i] = 0.0
        w = _map_fit(data, others, WEIGHTING_PRECISION, start=everyone)
        loss[i] = _log_loss(w, *data[i])
        kept = len(select(CutModel(**{**base.__dict__, "weights": tuple(w)}), studies[i])[0])
        ratio[i] = math.log((len(cuts[i]) + 1) / (kept + 1))
    by_loss = _down_weight(loss, 0.1 * float(np.median(loss)), upper_only=True)
    return np.minimum(by_loss, _down_weight(ratio, COUNT_SPREAD, upper_only=False))


def _down_weight(values: np.ndarray, floor: float, *, upper_only: bool) -> np.ndarray:
    """1 within OUTLIER_Z robust standard deviations (MAD, at least ``floor``) of the
    median, else (OUTLIER_Z / z)²."""
    centre = np.median(values)
    spread = max(1.4826 * float(np.median(np.abs(values - centre))), floor, 1e-6)
    z = (values - centre) / spread
    if not upper_only:
        z = np.abs(z)
    out = np.ones(len(values))
    bad = z > OUTLIER_Z
    out[bad] = (OUTLIER_Z / z[bad]) ** 2
    return out


def _min_segment(cuts: list[tuple[np.ndarray, float]], zero: float) -> float:
    """The convention's fineness: MIN_SEGMENT_FACTOR x the median over examples (cuts,
    fps) of each one's shortest inner segment, within [MIN_SEGMENT_S, MAX_SEGMENT_S];
    ``zero`` (the detector's setting) when no example has two cuts."""
    shortest = [np.diff(np.sort(c)).min() / f for c, f in cuts if len(c) > 1]
    if not shortest:
        return zero
    return float(np.clip(MIN_SEGMENT_FACTOR * np.median(shortest), MIN_SEGMENT_S,
                         MAX_SEGMENT_S))


def _placement(studies, cuts, tolerance_s: float) -> tuple[str, float]:
    """The placement step and shift (s) that follow the human cuts best, if clearly so:
    residuals (human - placed) of the zero-shot cuts matched to a human cut, each take's
    median first and the median over takes after (a take with odd cuts moves it little)."""
    zero = shipped_stage({"onset": True})
    per_take = {name: [] for name in PLACEMENTS}
    count = 0
    for one, c in zip(studies, cuts, strict=True):
        fps = float(one["fps"])
        tol = int(round(tolerance_s * fps))
        stages = one["stages"][one["zero_shot"]]
        for j, name in enumerate(PLACEMENTS):
            ci, ti = metrics.match(stages[:, j], c, tolerance=tol)
            if len(ci):
                per_take[name].append((c[ti] - stages[ci, j]) / fps)
        count += len(metrics.match(stages[:, PLACEMENTS.index(zero)], c, tolerance=tol)[0])
    if count < PLACEMENT_MIN_CUTS or len(per_take[zero]) < PLACEMENT_MIN_TAKES:
        return zero, 0.0

    def error(name, offset):
        return float(np.median([np.median(np.abs(r - offset)) for r in per_take[name]]))

    base = error(zero, 0.0)
    best, best_error = (zero, 0.0), base
    for name in PLACEMENTS:
        if not per_take[name]:
            continue
        offset = float(np.median([np.median(r) for r in per_take[name]]))
        if error(name, offset) < best_error:
            best, best_error = (name, round(offset, 4)), error(name, offset)
    ratio, seconds = PLACEMENT_GAIN
    if best_error > min((1 - ratio) * base, base - seconds):
        return zero, 0.0
    return best
