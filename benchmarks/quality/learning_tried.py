"""Ways of labelling a reviewed take's candidates tried for the learner and not shipped,
scored beside the shipped one in the learning-curve run.

The learner labels a candidate true when it is matched one-to-one to a human cut within
the tolerance (``motionlib.adapt._learner._labelled``). Where a take's candidates lie
closer together than the tolerance, several stand within it of one cut and all but the
matched one are labelled false, though keeping any of them would score the same. Two
other labellings:

- *near cuts positive*: every candidate within the tolerance of a human cut is true;
- *near cuts left out*: the matched one is true, the others near a cut are not learnt
  from.

Each replaces ``_labelled`` for the length of a ``with labelled_as(...)`` block, so that
the curve, the ceiling's best count and the poisoning case are scored exactly as for the
shipped learner. A labelling is shipped only when no by-subject row of the curve is
worse and the poisoning targets still hold (``learning.print_tried`` scores them);
``docs/learning.md`` records the outcome.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from motionlib import metrics
from motionlib.adapt import _candidates, _learner


def _near(model, one: dict, cuts: np.ndarray):
    """(frames, matched, near): the candidates placed as ``model`` places them, the ones
    matched one-to-one to a human cut, and the ones within the tolerance of any."""
    frames = _learner.placed(model, one)
    tol = int(round(model.tolerance_s * float(one["fps"])))
    matched = np.zeros(len(frames), dtype=bool)
    matched[metrics.match(frames, cuts, tolerance=tol)[0]] = True
    near = _candidates._near(frames, cuts, np.ones(len(cuts)), tol) > 0
    return frames, matched, near


def near_positive(model, one: dict, cuts: np.ndarray):
    _, _, near = _near(model, one, cuts)
    return _learner.design(one["features"]), near.astype(float)


def near_left_out(model, one: dict, cuts: np.ndarray):
    _, matched, near = _near(model, one, cuts)
    keep = matched | ~near
    return _learner.design(one["features"])[keep], matched[keep].astype(float)


LABELLINGS = {"near cuts positive": near_positive, "near cuts left out": near_left_out}


@contextmanager
def labelled_as(labelling):
    """The learner labels candidates with ``labelling`` inside the block."""
    shipped = _learner._labelled
    _learner._labelled = labelling
    try:
        yield
    finally:
        _learner._labelled = shipped
