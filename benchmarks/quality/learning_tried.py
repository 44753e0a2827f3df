"""Ways of labelling a reviewed take's candidates tried for the learner and not shipped,
scored beside the shipped one in the learning-curve run.

The learner labels a candidate true when it is matched one-to-one to a human cut within
the tolerance (``motionlib.adapt.matched_labels``). Where a take's candidates lie
closer together than the tolerance, several stand within it of one cut and all but the
matched one are labelled false, though keeping any of them would score the same. Two
other labellings:

- *near cuts positive*: every candidate within the tolerance of a human cut is true;
- *near cuts left out*: the matched one is true, the others near a cut are not learnt
  from.

Each is the ``labels`` every fit of the learning benchmark passes to
``adapt.fit_cut_model`` for the length of a ``with learning.labelled_as(...)`` block, so that the
curve, the ceiling's best count and the poisoning case are scored exactly as for the
shipped learner. A labelling is shipped only when no by-subject row of the curve is
worse and the poisoning targets still hold (``learning.print_tried`` scores them);
``docs/learning.md`` records the outcome.
"""

from __future__ import annotations

import numpy as np

from motionlib import adapt, metrics


def _near(model, one: dict, cuts: np.ndarray):
    """(frames, matched, near): the candidates placed as ``model`` places them, the ones
    matched one-to-one to a human cut, and the ones within the tolerance of any."""
    frames = adapt.placed(model, one)
    tol = int(round(model.tolerance_s * float(one["fps"])))
    matched = np.zeros(len(frames), dtype=bool)
    matched[metrics.match(frames, cuts, tolerance=tol)[0]] = True
    near = np.zeros(len(frames), dtype=bool)
    if len(cuts):
        near = np.abs(frames[:, None] - np.asarray(cuts)[None, :]).min(axis=1) <= tol
    return frames, matched, near


def near_positive(model, one: dict, cuts: np.ndarray):
    _, _, near = _near(model, one, cuts)
    return np.arange(len(near)), near.astype(float)


def near_left_out(model, one: dict, cuts: np.ndarray):
    _, matched, near = _near(model, one, cuts)
    keep = matched | ~near
    return np.flatnonzero(keep), matched[keep].astype(float)


LABELLINGS = {"near cuts positive": near_positive, "near cuts left out": near_left_out}
