"""The label-aware cut scorer: what the frame posterior says at every candidate cut.

The cut learner (``motionlib.adapt``) scores candidates by how much the motion changes.
A studio that cuts where its *actions* change needs what changes: at every candidate,
from the posterior of :mod:`motionlib.labelling` over a window on each side
(``WINDOW_S``), the evidence ``EVIDENCE``:

- ``mix``: how much the label mix differs across it (total variation, 0..1);
- ``change``: whether the most likely label changes;
- ``opens`` / ``closes``: how much more likely "unlabelled" is before than after it (a
  labelled stretch opens) or after than before (one closes);
- ``same``: the same label holds on both sides (a change inside one action);
- ``length``: how usual the segment it closes is for its label's length (Gaussian
  log-likelihood of the log length, 0 at the label's mean);
- ``decoded`` / ``decoded_labelled``: how near (``exp(-d / WINDOW_S)``) the nearest
  change of the decoded label sequence (``labelling.decode``) lies, of any change and of
  one between two labelled stretches.

A :class:`LabelCutModel` adds them to the cut model's logit in a logistic scorer whose
prior is the cut model itself (weight 1 on its logit, 0 on every evidence): with no frame
model, or no evidence fitted, it keeps exactly the cut model's cuts, so k = 0 is exactly
zero-shot. Its evidence weights are fitted on the reviewed takes' candidates, each take
seen through a frame model fitted without its fold (``labelling.out_of_fold``; folds by
performer where the caller knows them, ``groups``).

Where a studio cuts exactly where its actions change, the decoded label changes are
themselves the cuts (``mode`` "decoded"), or say which boundary while the cut model's
likeliest nearby candidate says where (``mode`` "snapped"). Which of the four (the cut model's cuts, the
joint scorer's, the decoded changes, the snapped ones) a project gets is chosen on its reviewed takes, each
seen out of fold: the one with the best mean F1 there, the cut model on a tie. The
choice reads the reviewed takes only; how the options came to be is in docs/learner.md.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize
from scipy.special import expit

from motionlib import metrics
from motionlib.labelling import FrameModel, decode, out_of_fold
from motionlib.labelling import _folds as labelling_folds

EVIDENCE = ("mix", "change", "opens", "closes", "same", "length", "decoded",
            "decoded_labelled")
WINDOW_S = 1.0
# Strength of the prior that keeps the scorer at the cut model (pseudo-observations).
PRECISION = 10.0
MODES = ("scored", "decoded", "snapped")
# The count calibration's search range and bisection steps (logits).
CALIBRATION_RANGE = 8.0
CALIBRATION_STEPS = 12


def evidence(post: np.ndarray, frames, fps: float, model: FrameModel) -> np.ndarray:
    """(n, len(EVIDENCE)) the evidence at candidate ``frames`` (take frames) of a take
    whose per-frame posterior is ``post`` (n_frames, n_labels)."""
    frames = np.asarray(frames, dtype=np.int64)
    n = len(post)
    if len(frames) == 0 or n == 0:
        return np.zeros((len(frames), len(EVIDENCE)))
    w = max(1, int(round(WINDOW_S * fps)))
    cum = np.vstack([np.zeros((1, post.shape[1])), np.cumsum(post, axis=0)])
    lo, mid, hi = np.clip(frames - w, 0, n), np.clip(frames, 1, n - 1), np.clip(frames + w, 0, n)
    left = (cum[mid] - cum[lo]) / np.maximum(mid - lo, 1)[:, None]
    right = (cum[hi] - cum[mid]) / np.maximum(hi - mid, 1)[:, None]
    a, b = left.argmax(axis=1), right.argmax(axis=1)
    opening = left[:, 0] - right[:, 0]
    near, near_labelled = _decoded(post, mid, fps, model)
    return np.column_stack([near, near_labelled, 0.5 * np.abs(left - right).sum(axis=1), (a != b).astype(float),
                            np.maximum(opening, 0), np.maximum(-opening, 0),
                            ((a == b) & (a != 0)).astype(float),
                            _length(post, mid, fps, model)])[:, [2, 3, 4, 5, 6, 7, 0, 1]]


def _decoded(post, frames, fps, model: FrameModel) -> tuple[np.ndarray, np.ndarray]:
    """Closeness of each frame to the nearest decoded label change, and to the nearest
    one between two labelled stretches."""
    path = decode(model, post, fps)
    changes = np.flatnonzero(np.diff(path)) + 1
    both = changes[(path[changes - 1] != 0) & (path[changes] != 0)]
    return tuple(_closeness(frames, c, fps) for c in (changes, both))


def _closeness(frames: np.ndarray, marks: np.ndarray, fps: float) -> np.ndarray:
    if len(marks) == 0:
        return np.zeros(len(frames))
    at = np.clip(np.searchsorted(marks, frames), 1, len(marks)) if len(marks) > 1 else \
        np.ones(len(frames), dtype=np.int64)
    d = np.minimum(np.abs(frames - marks[at - 1]), np.abs(frames - marks[np.minimum(at, len(marks) - 1)]))
    return np.exp(-d / (WINDOW_S * fps))


def _length(post, frames, fps, model: FrameModel) -> np.ndarray:
    """Log-likelihood (up to a constant, floored at -8) of the run of the frame-wise most
    likely label that ends at each frame, under that label's usual log length."""
    best = post.argmax(axis=1)
    starts = np.concatenate([[0], np.flatnonzero(np.diff(best)) + 1])
    start = starts[np.searchsorted(starts, frames - 1, side="right") - 1]
    label = best[frames - 1]
    usual = np.asarray([model.lengths.get(n, (np.nan, 1.0)) for n in model.names])
    with np.errstate(invalid="ignore", divide="ignore"):
        z = (np.log(np.maximum(frames - start, 1) / fps) - usual[label, 0]) / usual[label, 1]
    out = np.where(np.isfinite(z), np.maximum(-0.5 * z * z, -8.0), 0.0)
    return out


@dataclass
class LabelCutModel:
    """A cut model and a frame model, and the weights that join them: logit =
    ``weights @ [cut logit, *evidence, 1]``."""

    frames: FrameModel | None
    weights: np.ndarray
    threshold: float = 0.0
    # or "decoded": the decoded label changes are the cuts; "snapped": each moved to the
    # cut model's likeliest candidate near it
    mode: str = "scored"

    @classmethod
    def identity(cls, frames: FrameModel | None = None) -> LabelCutModel:
        return cls(frames, _prior())


def _prior() -> np.ndarray:
    w = np.zeros(len(EVIDENCE) + 2)
    w[0] = 1.0
    return w


def candidate_logits(cut_model, study: dict) -> tuple[np.ndarray, np.ndarray]:
    """(logits, frames): the cut model's logit of every candidate of a study and its
    frame as the model places it."""
    from motionlib.adapt import placed
    from motionlib.adapt._model import scorer_inputs

    logits = scorer_inputs(cut_model, study) @ np.asarray(cut_model.weights)
    return logits - cut_model.threshold, placed(cut_model, study)


def design(cut_model, model: LabelCutModel, study: dict, post) -> tuple[np.ndarray, np.ndarray]:
    """(x, frames): the joint scorer's design rows of a study's candidates."""
    logits, frames = candidate_logits(cut_model, study)
    ev = np.zeros((len(frames), len(EVIDENCE))) if post is None or model.frames is None \
        else evidence(post, frames, float(study["fps"]), model.frames)
    return np.column_stack([logits, ev, np.ones(len(frames))]), frames


def select(cut_model, model: LabelCutModel, study: dict | None, post) -> tuple:
    """(cuts, probability): the candidates the joint scorer finds more likely true than
    not, most probable first, none within the cut model's shortest segment of a kept one."""
    if study is None or len(study["features"]) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    if model.mode in ("decoded", "snapped") and model.frames is not None and post is not None:
        cuts, prob = decoded_cuts(model.frames, post, float(study["fps"]))
        if model.mode == "snapped":
            logits, placed_at = candidate_logits(cut_model, study)
            cuts = snapped(cuts, placed_at, logits, cut_model.min_segment_s * float(study["fps"]))
        return cuts, prob
    x, frames = design(cut_model, model, study, post)
    logit = x @ model.weights
    order, kept = _ranked(logit, frames, int(round(cut_model.min_segment_s *
                                                    float(study["fps"]))))
    chosen = order[kept & (logit[order] > model.threshold)]
    chosen = chosen[np.argsort(frames[chosen], kind="stable")]
    return frames[chosen].astype(np.int64), expit(logit[chosen] - model.threshold)


def decoded_cuts(frames: FrameModel, post: np.ndarray, fps: float) -> tuple:
    """(cuts, probability): where the decoded label changes, each with how much the
    label mix differs across it."""
    path = decode(frames, post, fps)
    cuts = np.flatnonzero(np.diff(path)) + 1
    if len(cuts) == 0:
        return cuts.astype(np.int64), np.zeros(0)
    return cuts.astype(np.int64), evidence(post, cuts, fps, frames)[:, 0]


def snapped(cuts: np.ndarray, placed: np.ndarray, logits: np.ndarray, radius: float) -> np.ndarray:
    """Each decoded change moved to the candidate the cut model finds likeliest within
    ``radius`` frames of it (the decoded labels say which boundary, the cut model where
    the studio puts it); left where it is when no candidate is that near."""
    out = np.asarray(cuts, dtype=np.int64).copy()
    for j, c in enumerate(out):
        near = np.flatnonzero(np.abs(placed - c) <= radius)
        if len(near):
            out[j] = int(placed[near[np.argmax(logits[near])]])
    return np.unique(out)


def _ranked(logit: np.ndarray, frames: np.ndarray, gap: int) -> tuple[np.ndarray, np.ndarray]:
    """(order, kept): candidates from the most probable down, and which of them are no
    closer than ``gap`` frames to a more probable kept one. A candidate's fate depends
    only on those ranked before it, so one pass serves every threshold."""
    order = np.argsort(-logit, kind="stable")
    kept = np.zeros(len(order), dtype=bool)
    taken: list[int] = []
    for rank, i in enumerate(order.tolist()):
        f = int(frames[i])
        at = bisect.bisect_left(taken, f)
        if (at < len(taken) and taken[at] - f < gap) or (at and f - taken[at - 1] < gap):
            continue
        taken.insert(at, f)
        kept[rank] = True
    return order, kept


def fit_label_cuts(cut_model, frames: FrameModel | None, studies, examples, cuts,
                   *, tolerance_s: float, groups=None) -> LabelCutModel:
    """Fit the evidence weights on reviewed takes: ``studies`` (their candidates),
    ``examples`` (their ``FrameExample``s, in the order the frame model was fitted on)
    and ``cuts`` (their human cuts); ``groups`` (a key per take, e.g. its performer) make
    the folds, each take by itself when not given. With no frame model, or a single fold
    (no take can then be seen out of sample), the scorer stays the cut model's."""
    model = LabelCutModel.identity(frames)
    folds = labelling_folds(examples, groups)
    if frames is None or len(set(folds)) < 2:
        return model
    seen = out_of_fold(examples, folds)
    xs, ys, takes = [], [], []
    for study, example, c, got in zip(studies, examples, cuts, seen, strict=True):
        if study is None or len(study["features"]) == 0 or got is None:
            continue
        fold_model, at = got
        fold_model.sharpness = frames.sharpness
        post = _per_frame(at, example)
        x, placed = design(cut_model, LabelCutModel.identity(fold_model), study, post)
        y = np.zeros(len(placed))
        hit, _ = metrics.match(placed, np.asarray(c, dtype=np.int64),
                               tolerance=int(round(tolerance_s * float(study["fps"]))))
        y[hit] = 1.0
        xs.append(x)
        ys.append(y)
        gap = int(round(cut_model.min_segment_s * float(study["fps"])))
        changes = decoded_cuts(fold_model, post, float(study["fps"]))[0]
        takes.append(_Seen(placed, gap, np.asarray(c, dtype=np.int64), float(study["fps"]),
                           changes, snapped(changes, placed, x[:, 0], cut_model.min_segment_s
                                            * float(study["fps"]))))
    if not xs:
        return model
    weights = _map_fit(np.vstack(xs), np.concatenate(ys))
    ranked = []
    for x, y, take in zip(xs, ys, takes, strict=True):
        logit = x @ weights
        order, kept = _ranked(logit, take.placed, take.gap)
        ranked.append((logit[order][kept], int(y.sum())))
    options = [model, LabelCutModel(frames, weights, _calibrated(ranked)),
               LabelCutModel(frames, _prior(), 0.0, "decoded"),
               LabelCutModel(frames, _prior(), 0.0, "snapped")]
    # The gate: the option that cuts the reviewed takes (each seen out of fold) best.
    scores = [_mean_f1(option, xs, takes, tolerance_s) for option in options]
    return options[int(np.argmax(scores))]


@dataclass
class _Seen:
    """A reviewed take as the gate sees it: its candidates' frames, the shortest segment
    (frames), its human cuts, fps and the decoded changes of its out-of-fold posterior."""

    placed: np.ndarray
    gap: int
    cuts: np.ndarray
    fps: float
    decoded: np.ndarray
    snapped: np.ndarray


def _per_frame(at: np.ndarray, example) -> np.ndarray:
    frames = np.arange(example.n_frames)
    return at[np.clip(np.searchsorted(example.samples, frames), 0, len(at) - 1)]


def _mean_f1(model: LabelCutModel, xs, takes, tolerance_s) -> float:
    """Mean F1 over the reviewed takes of what ``model`` keeps among their candidates."""
    scores = []
    for x, take in zip(xs, takes, strict=True):
        if model.mode in ("decoded", "snapped"):
            found = take.decoded if model.mode == "decoded" else take.snapped
        else:
            logit = x @ model.weights
            order, kept = _ranked(logit, take.placed, take.gap)
            chosen = order[kept & (logit[order] > model.threshold)]
            found = np.sort(take.placed[chosen])
        scores.append(metrics.boundary_scores(
            found, metrics.as_windows(take.cuts), fps=take.fps,
            tolerance_s=tolerance_s)["f1"])
    return float(np.mean(scores)) if scores else 0.0


def _calibrated(ranked) -> float:
    """The threshold at which the median reviewed take keeps as many cuts as its
    reviewers made (``ranked``: each take's kept logits, descending, and its true count):
    the scorer's probabilities are too low where true cuts are rare among candidates."""
    def excess(t):
        return float(np.median([np.log((np.sum(kept > t) + 1) / (n + 1))
                                for kept, n in ranked]))
    lo, hi = -CALIBRATION_RANGE, CALIBRATION_RANGE
    for _ in range(CALIBRATION_STEPS):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if excess(mid) > 0 else (lo, mid)
    return round((lo + hi) / 2, 4)


def _map_fit(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Logistic regression with a Gaussian prior centred on the cut model."""
    prior = _prior()

    def objective(w):
        z = x @ w
        loss = np.sum(np.logaddexp(0, z) - y * z) + 0.5 * PRECISION * np.sum((w - prior) ** 2)
        grad = x.T @ (expit(z) - y) + PRECISION * (w - prior)
        return loss, grad
    return minimize(objective, prior, jac=True, method="L-BFGS-B").x
