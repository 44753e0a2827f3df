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
``adapt.fit_cut_model`` for the length of a ``with labelled_as(...)`` block, so that the
curve, the ceiling's best count and the poisoning case are scored exactly as for the
shipped learner. A labelling is shipped only when no by-subject row of the curve is
worse and the poisoning targets still hold; ``docs/learning.md`` records the outcome.
"""

from __future__ import annotations

import io
from contextlib import contextmanager

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


@contextmanager
def labelled_as(labelling):
    """Every fit of the learning benchmark labels candidates with ``labelling`` inside
    the block (``learning.LABELS``, its ``adapt.fit_cut_model(labels=...)``)."""
    from benchmarks.quality import learning

    shipped = learning.LABELS
    learning.LABELS = labelling
    try:
        yield
    finally:
        learning.LABELS = shipped


def print_tried(sets, curves: dict, poison: dict, out) -> None:
    """For each labelling: the by-subject curve (F1, edits) beside the shipped one, the
    best count at k = TARGET_K, the poisoning case, and whether the shipping rule holds."""
    from benchmarks.quality import learning

    chosen = [s for s in sets if s.by_subject and s.items]
    print("\n## Tried, not shipped: other labellings of the candidates the learner learns "
          "from (benchmarks/quality/learning_tried.py); by subject, out of sample", file=out)
    print("F1 / review edits per true cut, shipped -> tried; best count at "
          f"k={learning.TARGET_K} (oracle, as in the ceiling); poisoning mean dF1 under / "
          "over.", file=out)
    for name, labelling in LABELLINGS.items():
        worse = []
        with labelled_as(labelling):
            tried = {s.name: learning.curve(s) for s in chosen}
            tried_poison = learning.poisoning(sets, io.StringIO())
        for label in chosen:
            shipped, other = curves[label.name][0], tried[label.name]
            cells = []
            for k in learning.KS[1:]:
                (f0, e0, _), (f1, e1, _) = shipped[k][0], other[k][0]
                cells.append(f"k={k} {f0:.2f}/{e0:.2f} -> {f1:.2f}/{e1:.2f}")
                if f1 < f0 - 1e-9 or e1 > e0 + 1e-9:
                    worse.append(f"{label.name} k={k}")
            moved = "; ".join(f"{tried_poison[(label.name, m)][0]:+.3f}"
                              for m in ("under", "over"))
            print(f"{name:<20}{label.name:<10}" + ", ".join(cells) +
                  f"; best count {shipped.get('best count', np.nan):.2f} -> "
                  f"{other.get('best count', np.nan):.2f}; poisoning {moved}", file=out)
        broken = [f"{n} {m}" for (n, m), (mean, _) in tried_poison.items()
                  if abs(mean) >= learning.TARGET_POISON > abs(poison[(n, m)][0])]
        verdict = "shipping rule holds" if not worse and not broken else (
            "not shipped: " + ", ".join([*(f"worse at {w}" for w in worse),
                                         *(f"poisoning {b} no longer met" for b in broken)]))
        print(f"{name:<20}{verdict}", file=out)
