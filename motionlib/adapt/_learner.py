"""How a studio's convention is learnt from its reviewed takes: a :class:`CutModel`'s
scorer, fineness and placement fitted to example takes' candidates and human cuts.

Each example's candidates are labelled true or false against its human cuts (``labels``:
by default, a candidate matched one-to-one to a human cut within the tolerance is true,
:func:`matched_labels`), and the scorer is a maximum-a-posteriori logistic regression
over their evidence whose Gaussian prior is centred on the zero-shot decision (keep
exactly the zero-shot cuts): with no example it *is* the zero-shot detector, a few
examples move it a little, many move it as far as they agree. Takes are weighted before
the final fit: each is predicted by a model fitted on the others, and one that disagrees
far more than the rest (a reviewer who cut half the cuts, or twice as many) is
down-weighted, so that a minority of bad reviews cannot drag the model. Fineness and
placement are medians over takes for the same reason. How the fixed settings were
chosen is in ``docs/detector/adaptation.md``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from scipy.special import expit

from motionlib import metrics
from motionlib.adapt._model import (
    CutModel,
    placed,
    prior_weights,
    ranked,
    scorer_inputs,
    select,
)
from motionlib.segmenters.default import PLACEMENTS, shipped_stage

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


# How a study's candidates are labelled for the scorer: ``labels(model, study, cuts)``
# -> (rows, y), the candidates learnt from (indices into the study's candidates) and
# whether each is a human cut (0/1), with ``model`` placing the candidates (its placement
# and offset, already chosen) and ``cuts`` the take's human cuts (take frames).
Labels = Callable[[CutModel, dict, np.ndarray], tuple[np.ndarray, np.ndarray]]


def matched_labels(model: CutModel, one: dict, cuts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The shipped labelling (:data:`Labels`): every candidate is learnt from, and is a
    cut when, placed as ``model`` places it, it is matched one-to-one to a human cut
    within the model's tolerance."""
    frames = placed(model, one)
    y = np.zeros(len(frames))
    ci, _ = metrics.match(frames, cuts, tolerance=int(round(model.tolerance_s *
                                                               float(one["fps"]))))
    y[ci] = 1.0
    return np.arange(len(frames)), y


def _labelled(labels: Labels, model: CutModel, one: dict,
              cuts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(design matrix, 0/1 labels) of the candidates ``labels`` learns from."""
    rows, y = labels(model, one, cuts)
    return scorer_inputs(model, one)[rows], np.asarray(y, dtype=float)


def fit(studies: list[dict], cuts: list[np.ndarray], *, tolerance_s: float,
        zero_min_segment_s: float, choice: tuple | None = None, labels: Labels | None = None,
        given: np.ndarray | None = None):
    """Learn a :class:`CutModel` from example studies and their human cuts (take frames).

    ``labels`` says which candidates of a study the scorer learns from and which of them
    are human cuts (:data:`Labels`; :func:`matched_labels` when None). ``given`` (one per
    example, in (0, 1]; all 1 when None) multiplies each example's weight in the scorer's
    regression and its choice of prior: a cap on what a group of takes may count that the
    caller knows of (the takes of one annotator). Which takes are outliers, the count
    calibration and ``down_weighted`` stay the learner's own.

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
    labels = labels or matched_labels
    data = [_labelled(labels, base, one, c) for one, c in zip(studies, cuts, strict=True)]
    if choice is None or len(studies) < CV_TAKES:
        weights = _take_weights(base, studies, cuts, data)
    else:
        weights = np.asarray(choice[0], dtype=float)
    if len(studies) < CV_TAKES:  # one or two takes do not show how finely a studio cuts
        base = replace(base, min_segment_s=0.0)
    counted = weights * (np.ones(len(studies)) if given is None else np.asarray(given, dtype=float))
    if choice is None or len(studies) < CV_TAKES:
        precision, calibrate = _choose(base, studies, cuts, data, weights, counted)
    else:
        precision, calibrate = choice[1], choice[2]
    model = replace(base, weights=tuple(float(v) for v in _map_fit(data, counted, precision)),
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
    rows = []
    for one, c in zip(studies, cuts, strict=True):
        logits, _, _, kept = ranked(model, one)
        rows.append((-logits, np.concatenate([[0], np.cumsum(kept)]), len(c)))

    def excess(threshold):
        # The ranked candidates above the threshold are a prefix; count its kept ones.
        return float(np.median([
            math.log((kept[np.searchsorted(descending, -threshold, side="left")] + 1) /
                     (n_true + 1)) for descending, kept, n_true in rows]))
    lo, hi = -CALIBRATION_RANGE, CALIBRATION_RANGE
    for _ in range(CALIBRATION_STEPS):
        mid = (lo + hi) / 2
        if excess(mid) > 0:
            lo = mid
        else:
            hi = mid
    return round((lo + hi) / 2, 4)


def _choose(base: CutModel, studies, cuts, data, weights, counted) -> tuple[float, bool]:
    """(prior precision, calibrate the count): below CV_TAKES examples FIXED_PRECISION
    and no calibration (keep what is more likely true than not; ``_calibrated``
    otherwise); else the pair whose models, fitted without a fold of example takes, cut
    those takes with the best weighted mean F1 (at the model's tolerance), ties going
    to the stronger prior and to no calibration. Takes count by ``counted`` (their weights
    times the caller's); which are trusted for the count is the learner's ``weights``."""
    n = len(data)
    if n < CV_TAKES:
        return FIXED_PRECISION, False
    folds = min(n, CV_FOLDS)
    best, best_score = (math.inf, False), -math.inf
    for precision in PRECISIONS:
        scores = {False: 0.0, True: 0.0}
        for fold in range(folds):
            held = np.arange(n) % folds == fold
            weights_in = np.where(held, 0.0, counted)
            fitted = replace(base, weights=tuple(_map_fit(data, weights_in, precision)))
            trusted = [i for i in range(n) if not held[i] and weights[i] >= 0.5]
            calibrated = replace(fitted, threshold=_calibrated(
                fitted, [studies[i] for i in trusted], [cuts[i] for i in trusted]))
            for calibrate, m in ((False, fitted), (True, calibrated)):
                for i in np.flatnonzero(held).tolist():
                    found = select(m, studies[i])[0]
                    scores[calibrate] += counted[i] * metrics.boundary_scores(
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
    w0 = prior_weights()
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
