"""Learning a studio's own cutting convention from its reviewed takes.

A studio's annotators have a convention: what counts as a boundary, how finely they
segment, where exactly the cut goes. Given example takes with their human cuts,
:func:`fit_cut_model` learns that convention as a :class:`CutModel`, and :func:`detect`
cuts a new take with it:

1. every take is described by an over-complete set of candidate cuts (the zero-shot cuts,
   every weaker novelty peak, the peaks of short novelty windows), each with its frame at
   each placement step (``_candidates``) and a few evidence features (``_evidence``):
   the take's *study* (:func:`study`), kept per example in a :class:`Studies` store;
2. each example's candidates are labelled against its human cuts (``labels``,
   :func:`matched_labels` by default), and a logistic scorer over their evidence, whose
   prior is the zero-shot decision, is fitted to them, with the convention's shortest
   segment and the placement step and shift the examples follow (``_learner``);
3. a :class:`CutModel` keeps a take's candidates more likely true than not, no two closer
   than that shortest segment, each cut where its placement puts it (``_model``:
   :func:`cuts_in` from a study, :func:`detect` from a take).

With no example the model is the zero-shot detector (:meth:`CutModel.zero_shot`); each
example moves it as far as the examples agree, and a take that disagrees with the others
(a reviewer who under- or over-cut it) is weighted down. A take's candidates do not depend
on its cuts: stored once (``studies``), they serve every refit, so retraining after one
more reviewed take analyses only that take. :func:`score` gives a model's figure on a
reviewed take. Models stored in the first format (``ThresholdModel``, ``_threshold``) load
and detect exactly as before; nothing learns that format any more. How the design and its
fixed settings were chosen: ``docs/detector/adaptation.md``.

Where new work goes: evidence a take alone gives is a row of ``_evidence.EVIDENCE`` and
a column of its ``evidence`` (its prior weight is 0, so the zero-shot model stays the
zero-shot detector); evidence that needs a model of the other reviewed takes (what
happens at each frame, say) is fitted in ``_learner.fit`` beside the scorer, from what
the studies keep of each take (a study may hold more arrays than the candidates'), is
carried by the :class:`CutModel`, and joins the stored evidence where fitting and
selecting read a study (``_model.scorer_inputs``). The learner reads the detector through
its public steps only (``segmenters.default``: ``analyse``, ``peaks``, ``place``,
``peak_support``, ``place_samples``).

Pure numpy/scipy, no Django; the service stores ``model.to_json()`` and reads it back
with :meth:`CutModel.from_json`.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from motionlib import metrics
from motionlib.adapt import _learner
from motionlib.adapt._candidates import candidates_of, study_take
from motionlib.adapt._examples import (
    EXAMPLE_COLUMNS,
    Example,
    ExampleError,
    as_example,
    checked_cuts,
    read_examples,
)
from motionlib.adapt._learner import Labels, matched_labels
from motionlib.adapt._model import FORMAT, CutModel, placed, select
from motionlib.adapt._studies import MemoryStudies, Studies, kept_study
from motionlib.adapt._threshold import ThresholdModel, detect_threshold
from motionlib.points import segmenter_input
from motionlib.segmenters.base import Segmentation
from motionlib.segmenters.default import Default

__all__ = [
    "EXAMPLE_COLUMNS",
    "FORMAT",
    "CutModel",
    "Example",
    "ExampleError",
    "Labels",
    "MemoryStudies",
    "Refits",
    "Studies",
    "ThresholdModel",
    "cuts_in",
    "detect",
    "example_study",
    "fit_cut_model",
    "matched_labels",
    "placed",
    "read_examples",
    "score",
    "score_cuts",
    "study",
]


def fit_cut_model(examples: Sequence, *, studies: Studies | None = None,
                  base: dict | None = None, tolerance_s: float = 1.0,
                  labels: Labels | None = None) -> CutModel:
    """Learn a studio's convention from example takes with human cuts.

    Parameters
    ----------
    examples : sequence of (take, cuts), or of :class:`Example`; cuts are 0-based take
        frames where a new segment starts (a take with no cut is a valid example: one
        activity throughout). Each take is analysed once, in order, and not kept.
    studies : where each keyed :class:`Example`'s candidates are kept. They depend on the
        take and ``base`` only, not on its cuts: a stored example is neither read nor
        analysed again, so refitting after one more reviewed take, or after a review
        changed a take's cuts, analyses at most that one take; the model is the same as
        without ``studies``.
    base : the ``default`` segmenter's parameters the candidates are made with (its
        zero-shot settings when None); detect with the same (``detect(take, model,
        **base)``).
    tolerance_s : how far (s) a candidate may lie from a human cut to count as it: the
        precision the studio reviews at.
    labels : which candidates of an example the scorer learns from, and which of them
        are human cuts (:data:`Labels`): :func:`matched_labels` when None, the shipped
        labelling; another is for trying a labelling out.

    Returns
    -------
    CutModel; one example is enough, more make it surer.

    Raises
    ------
    ExampleError (a ValueError) naming the take and the value: an empty example list, a cut
    outside the take, a take too short to analyse; ValueError for a tolerance that is
    not a positive number.
    """
    return Refits(examples, studies=studies, base=base, tolerance_s=tolerance_s,
                  labels=labels).model


class Refits:
    """The model :func:`fit_cut_model` learns from ``examples`` (``.model``, the same), and
    refits of it without one example (:meth:`without`), as leave-one-take-out scoring
    makes them.

    A refit keeps what the full fit chose from all the examples (their weights, the
    prior's strength, whether the count is calibrated) and fits the scorer, fineness and
    placement on the others: a single regression instead of a fit's dozens. The choice
    has seen the left-out example, a small optimism that a candidate and the model it is
    compared with share when both are scored this way.
    """

    def __init__(self, examples: Sequence, *, studies: Studies | None = None,
                 base: dict | None = None, tolerance_s: float = 1.0,
                 labels: Labels | None = None):
        if len(examples) == 0:
            raise ExampleError("no example takes to learn from")
        if not (isinstance(tolerance_s, int | float) and 0 < tolerance_s <= 10):
            raise ExampleError(f"tolerance_s must be a number of seconds in (0, 10], "
                               f"got {tolerance_s!r}")
        p = Default.validate_params(base or {})
        checked = [(example, checked_cuts(example)) for example in map(as_example, examples)]
        self._found = [kept_study(example, p, studies) for example, _ in checked]
        self._cuts = [cuts for _, cuts in checked]
        self._given = np.array([_weight(example) for example, _ in checked])
        self._settings = {"tolerance_s": float(tolerance_s),
                          "zero_min_segment_s": p["min_segment_s"], "labels": labels}
        self.model, self._choice = _learner.fit(self._found, self._cuts, given=self._given,
                                                **self._settings)

    def without(self, i: int) -> CutModel | None:
        """The model refitted without example ``i`` (None when it was the only one)."""
        keep = [j for j in range(len(self._found)) if j != i]
        if not keep:
            return None
        weights, precision, calibrate = self._choice
        model, _ = _learner.fit([self._found[j] for j in keep], [self._cuts[j] for j in keep],
                                choice=(weights[keep], precision, calibrate),
                                given=self._given[keep], **self._settings)
        return model


def _weight(example: Example) -> float:
    """An example's given weight, checked: a number in (0, 1]."""
    w = example.weight
    if not (isinstance(w, int | float) and not isinstance(w, bool) and 0 < w <= 1):
        raise ExampleError(f"{example.name}: weight must be a number in (0, 1], got {w!r}")
    return float(w)


def example_study(example: Example, *, studies: Studies | None = None,
                  base: dict | None = None) -> dict:
    """The candidates of an example's take (:func:`study`), as :func:`fit_cut_model`
    finds them: read from ``studies`` when kept there, else computed (and kept). With
    :func:`cuts_in` they give what a model detects in that take without reading it again.

    Raises
    ------
    ExampleError for a take too short to analyse.
    """
    return kept_study(as_example(example), Default.validate_params(base or {}), studies)


def study(take, **params) -> dict[str, np.ndarray] | None:
    """The candidates of ``take`` a model chooses among (arrays, see ``_candidates``),
    with the ``default`` segmenter's ``params``; None for a take too short to analyse.
    Computing them is most of detection: a benchmark that scores many models on one
    take computes them once and calls :func:`cuts_in`."""
    return study_take(take, Default.validate_params(params))


def cuts_in(arrays: dict | None, model: CutModel) -> np.ndarray:
    """The cuts (take frames) ``model`` keeps among a take's candidates (:func:`study`)."""
    if arrays is None:
        return np.zeros(0, dtype=np.int64)
    return select(model, arrays)[0]


def detect(take, model: CutModel | ThresholdModel | None = None, **params) -> Segmentation:
    """Candidate cuts of ``take``; ``model=None`` is the zero-shot default detector.

    ``params`` are the ``default`` segmenter's parameters (validated with its schema).
    A :class:`CutModel` keeps the candidates its scorer finds more likely true than not
    (confidence: that probability), at its placement step and offset; a
    ``ThresholdModel`` (format 1) detects as it always did.

    Returns
    -------
    Segmentation, as ``Default(**params).fit_predict(take)``.
    """
    if model is None:
        return Default(**params).fit_predict(take)
    if isinstance(model, ThresholdModel):
        return detect_threshold(take, model, **params)
    start = time.perf_counter()
    found = candidates_of(segmenter_input(take, Default.name), Default.validate_params(params))
    if found is None:  # too short to compare anything: no cuts, as the detector says
        result = Segmentation(np.zeros(0, np.int64), np.zeros(0),
                              {"novelty": np.zeros(take.n_frames)})
    else:
        arrays, analysis, speed = found
        cuts, prob = select(model, arrays)
        result = analysis.segmentation(cuts - analysis.first, prob, speed)
        result = result.checked(int(arrays["n_frames"]))
    result.timings["total"] = time.perf_counter() - start
    return result


def score(model: CutModel | ThresholdModel | None, take, cuts, *, tolerance_s: float = 1.0,
          **params) -> dict[str, float]:
    """How well ``model`` cuts a reviewed take: its figure for the studio.

    ``cuts`` are the take's human cuts (0-based frames, or ``(n, 3)`` windows).

    Returns
    -------
    dict: ``f1``, ``precision``, ``recall`` within ``tolerance_s``; ``edits_per_cut``
    (review deletes, inserts and moves per human cut, matched within ``tolerance_s``);
    ``median_error_s`` (placement error of the matched cuts, NaN if none); ``n_cuts``
    (the model's) and ``n_true``.
    """
    found = detect(take, model, **params).cuts
    return score_cuts(found, cuts, fps=float(take.fps), tolerance_s=tolerance_s)


def score_cuts(found, cuts, *, fps: float, tolerance_s: float = 1.0) -> dict[str, float]:
    """:func:`score` for cuts already found."""
    truth = metrics.as_windows(cuts)
    row = metrics.boundary_scores(found, truth, fps=fps, tolerance_s=tolerance_s)
    return {"f1": row["f1"], "precision": row["precision"], "recall": row["recall"],
            "edits_per_cut": metrics.edit_cost(found, truth, fps=fps,
                                               match_s=tolerance_s)["edits_per_cut"],
            "median_error_s": metrics.median_error_s(found, truth, fps=fps,
                                                     tolerance_s=tolerance_s),
            "n_cuts": len(found), "n_true": len(truth)}
