"""The oracle ceiling of the learning curve: what the best choice among a take's
candidates could score against that take's own labels.

A model keeps a subset of a take's candidates (``adapt.study``), each at one of its
placement steps. The oracle chooses that subset knowing the labels: true cuts are
matched one-to-one to candidates within the set's tolerance (a candidate at any of its
placement steps, the one nearest the cut), as many as can be, then as near as can be,
and keeps exactly the matched candidates. That gives

- *candidate recall*: the share of true cuts with a candidate within tolerance;
- *ceiling F1 and edits*: the oracle subset scored like any model (F1 at the set's
  tolerance, review edits per true cut; no delete, and a move wherever the nearest
  candidate is further than the snap window);
- *best count*: the learnt model's own ranking (``k`` reviewed takes, as in the curve)
  with the number of cuts set by the labels: how far the ranking, rather than where it
  is cut off, holds a model back.

It uses the scored take's labels: an upper bound that separates what the candidates
allow from what the scorer makes of them, never a result.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.optimize import linear_sum_assignment

from motionlib import adapt, metrics

# The logit thresholds the best-count search tries (the count falls as it rises).
THRESHOLDS = np.linspace(-12.0, 12.0, 193)


def oracle_cuts(study: dict | None, truth, *, fps: float, tolerance_s: float) -> np.ndarray:
    """The candidates (take frames, sorted) an oracle keeps for ``truth`` ((n, 3)
    windows or (n,) cuts): the most true cuts matched one-to-one within ``tolerance_s``,
    each candidate at its placement step nearest its cut, the least total distance."""
    win = metrics.as_windows(truth)
    if study is None or len(study["stages"]) == 0 or len(win) == 0:
        return np.zeros(0, dtype=np.int64)
    stages = np.asarray(study["stages"], dtype=np.int64)  # (n_cand, n_steps)
    tol = int(round(tolerance_s * fps))
    inside = (stages[:, :, None] >= win[None, None, :, 0] - tol) & (
        stages[:, :, None] <= win[None, None, :, 2] + tol)
    dist = np.where(inside, np.abs(stages[:, :, None] - win[None, None, :, 1]), np.inf)
    step = dist.argmin(axis=1)  # (n_cand, n_true): each pair's nearest step
    best = dist.min(axis=1)
    feasible = np.isfinite(best)
    if not feasible.any():
        return np.zeros(0, dtype=np.int64)
    # As metrics.match: an infeasible pair costs more than any set of feasible ones.
    big = best[feasible].sum() + 1.0
    rows, cols = linear_sum_assignment(np.where(feasible, best, big))
    ok = feasible[rows, cols]
    rows, cols = rows[ok], cols[ok]
    return np.sort(stages[rows, step[rows, cols]])


def take_ceiling(study: dict | None, truth, *, fps: float, tolerance_s: float) -> np.ndarray:
    """[candidate recall, ceiling F1, ceiling edits per true cut] of one take."""
    chosen = oracle_cuts(study, truth, fps=fps, tolerance_s=tolerance_s)
    s = adapt.score_cuts(chosen, truth, fps=fps, tolerance_s=tolerance_s)
    return np.array([s["recall"], s["f1"], s["edits_per_cut"]])


def best_count(study: dict | None, truth, model: adapt.CutModel, *, fps: float,
               tolerance_s: float) -> float:
    """The best F1 of ``model``'s ranking of a take's candidates over every count
    (every threshold of ``THRESHOLDS``), the count chosen against ``truth``."""
    best = 0.0
    seen: set[int] = set()
    for threshold in [model.threshold, *THRESHOLDS]:
        found = adapt.cuts_in(study, replace(model, threshold=float(threshold)))
        if len(found) in seen:
            continue
        seen.add(len(found))
        best = max(best, adapt.score_cuts(found, truth, fps=fps,
                                          tolerance_s=tolerance_s)["f1"])
    return best
