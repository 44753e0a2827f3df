"""Boundary metrics: how well candidate cuts match true cuts, and what fixing them costs.

A true cut is a window ``(lo, mid, hi)`` of take frames: annotators who mark transition
windows (e.g. the CMU subject-86 labels) accept a cut anywhere in ``[lo, hi]``, with
``mid`` their best estimate; a plain labelled cut is ``lo == mid == hi``.

Matching is one-to-one and optimal: among all assignments of candidates to true cuts
where each pair is within tolerance (``lo - tol <= c <= hi + tol``), the one with the
most pairs and, among those, the smallest total ``|c - mid|`` (Hungarian algorithm,
``scipy.optimize.linear_sum_assignment``).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from motionlib.errors import InputError


def as_windows(truth) -> np.ndarray:
    """True cuts as an ``(n, 3)`` int array of ``(lo, mid, hi)`` frames, sorted by mid.

    Accepts plain cut frames ``(n,)`` or windows ``(n, 3)``; a window given out of order
    is repaired to ``lo <= mid <= hi``.
    """
    arr = np.asarray(truth, dtype=np.int64)
    if arr.ndim == 1:
        arr = np.repeat(arr[:, None], 3, axis=1)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"truth: expected (n,) cuts or (n, 3) windows, got shape {arr.shape}")
    arr = np.sort(arr, axis=1)
    return arr[np.argsort(arr[:, 1], kind="stable")]


def match(candidates, truth, *, tolerance: int) -> tuple[np.ndarray, np.ndarray]:
    """Optimal one-to-one matching of candidate cuts to true cuts.

    Parameters
    ----------
    candidates : (n_cand,) frames.
    truth : true cuts, see ``as_windows``.
    tolerance : frames a candidate may lie outside a true cut's window.

    Returns
    -------
    cand_idx, truth_idx : (n_pairs,) int indices of the matched pairs.
    """
    cand = np.asarray(candidates, dtype=np.int64).reshape(-1)
    win = as_windows(truth)
    empty = np.zeros(0, dtype=np.int64)
    if len(cand) == 0 or len(win) == 0:
        return empty, empty
    feasible = (cand[:, None] >= win[None, :, 0] - tolerance) & (
        cand[:, None] <= win[None, :, 2] + tolerance
    )
    dist = np.abs(cand[:, None] - win[None, :, 1]).astype(float)
    # An infeasible pair costs more than any set of feasible pairs, so the assignment
    # maximises the number of feasible pairs first and their total distance second.
    big = dist[feasible].sum() + 1.0 if feasible.any() else 1.0
    rows, cols = linear_sum_assignment(np.where(feasible, dist, big * (1 + dist)))
    ok = feasible[rows, cols]
    return rows[ok].astype(np.int64), cols[ok].astype(np.int64)


def boundary_scores(candidates, truth, *, fps: float, tolerance_s: float) -> dict[str, float]:
    """Precision, recall and F1 of candidate cuts within ``tolerance_s`` seconds.

    With no candidates precision is 1 (nothing wrong was proposed); with no true cuts
    recall is 1; F1 is 0 when both precision and recall are 0.
    """
    cand = np.asarray(candidates).reshape(-1)
    win = as_windows(truth)
    pairs, _ = match(cand, win, tolerance=int(round(tolerance_s * fps)))
    precision = len(pairs) / len(cand) if len(cand) else 1.0
    recall = len(pairs) / len(win) if len(win) else 1.0
    total = precision + recall
    f1 = 2 * precision * recall / total if total > 0 else 0.0
    return {"precision": precision, "recall": recall, "f1": f1, "matched": len(pairs)}


def edit_cost(
    candidates, truth, *, fps: float, match_s: float = 1.0, snap_s: float = 0.25
) -> dict[str, float]:
    """Review edits needed to turn the candidates into the true cuts.

    Candidates are matched to true cuts within ``match_s`` seconds. Each unmatched
    candidate costs a delete, each unmatched true cut an insert, and each matched
    candidate outside its true cut's window (widened to at least ``mid ± snap_s``) a
    move; a matched candidate inside that window is accepted as is.

    Returns
    -------
    dict with ``deletes``, ``inserts``, ``moves``, ``edits`` (their sum) and
    ``edits_per_cut`` (edits / number of true cuts; edits itself when there are none).
    """
    cand = np.asarray(candidates, dtype=np.int64).reshape(-1)
    win = as_windows(truth)
    ci, ti = match(cand, win, tolerance=int(round(match_s * fps)))
    snap = int(round(snap_s * fps))
    lo = np.minimum(win[ti, 0], win[ti, 1] - snap)
    hi = np.maximum(win[ti, 2], win[ti, 1] + snap)
    moves = int(np.count_nonzero((cand[ci] < lo) | (cand[ci] > hi)))
    deletes, inserts = len(cand) - len(ci), len(win) - len(ti)
    edits = deletes + inserts + moves
    return {
        "deletes": deletes,
        "inserts": inserts,
        "moves": moves,
        "edits": edits,
        "edits_per_cut": edits / len(win) if len(win) else float(edits),
    }


def _matched(candidates, truth, fps: float, tolerance_s: float):
    """The candidate frames and true windows (rows lo, mid, hi) of the pairs matched within
    ``tolerance_s``, in matching order."""
    cand = np.asarray(candidates, dtype=np.int64).reshape(-1)
    win = as_windows(truth)
    ci, ti = match(cand, win, tolerance=int(round(tolerance_s * fps)))
    return cand[ci], win[ti]


def median_error_s(candidates, truth, *, fps: float, tolerance_s: float = 1.0) -> float:
    """Median ``|candidate - mid|`` in seconds over pairs matched within ``tolerance_s``.

    NaN when nothing matches.
    """
    cand, win = _matched(candidates, truth, fps, tolerance_s)
    if len(cand) == 0:
        return float("nan")
    return float(np.median(np.abs(cand - win[:, 1]))) / fps


def in_window_fraction(candidates, truth, *, fps: float, tolerance_s: float = 1.0) -> float:
    """Fraction of the matched cuts that lie inside their true cut's window ``[lo, hi]``.

    Pairs are matched within ``tolerance_s`` as for ``median_error_s``; only true cuts
    with a labelled transition window (``lo < hi``) count, since a plain cut's window is
    one frame. NaN when no such true cut is matched (e.g. labels without windows).
    """
    cand, win = _matched(candidates, truth, fps, tolerance_s)
    windowed = win[:, 0] < win[:, 2]
    if not windowed.any():
        return float("nan")
    c, w = cand[windowed], win[windowed]
    return float(np.mean((c >= w[:, 0]) & (c <= w[:, 2])))


def evaluate(candidates, truth, *, fps: float) -> dict[str, float]:
    """The benchmark's row: P/R/F1 at 0.5 s and 1 s, edits per true cut, median error,
    and the fraction of matched cuts inside a labelled transition window."""
    row: dict[str, float] = {}
    for tol in (0.5, 1.0):
        scores = boundary_scores(candidates, truth, fps=fps, tolerance_s=tol)
        for key in ("precision", "recall", "f1"):
            row[f"{key}@{tol:g}s"] = scores[key]
    row["edits_per_cut"] = edit_cost(candidates, truth, fps=fps)["edits_per_cut"]
    row["median_error_s"] = median_error_s(candidates, truth, fps=fps)
    row["in_window"] = in_window_fraction(candidates, truth, fps=fps)
    return row
