"""The ``short_activity`` option: the far side of activities too short for the windows."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.signal import find_peaks
from scipy.spatial.distance import cdist

if TYPE_CHECKING:
    from motionlib.segmenters.default._analysis import Analysis

# How far (s) a short-window peak may lie from the long-window peak or shoulder it confirms.
SHORT_PEAK_TOLERANCE_S = 0.5


def short_activity_peaks(analysis: Analysis, peaks: np.ndarray, strength: np.ndarray,
                         p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Add the far side of activities too short for the long windows (step 4b).

    Between two long activities, windows of ``scale_min_s`` and more see a short one as
    a single broad peak: the boundary it does not pick is at most a *shoulder* (a local
    maximum without the prominence) at most ``scale_min_s`` away. Windows of
    ``min_segment_s`` (the shortest activity to find) resolve the two. Such a shoulder
    becomes a cut, at its short-window peak, when the short-window novelty has a peak
    within ``SHORT_PEAK_TOLERANCE_S`` of both the shoulder and the kept peak, each
    ``short_activity`` times as prominent as the median short-window peak inside the
    activities (farther than ``scale_min_s / 2`` from every kept peak) and at least
    ``prominence``: short windows also fire on changes within an activity, so only a
    pair that stands well above the take's own such changes counts. With
    ``short_uniformity`` the stretch between the two must also look like one activity
    (``mixing`` at most that), not like the passage from one activity into the next.

    Returns
    -------
    peaks, evidence : as ``_peaks.select_peaks``, sorted; an added peak's evidence is the
        ``prominence`` setting (confidence 0.5, the weakest peak kept on its own).
    """
    if len(peaks) == 0:
        return peaks, strength
    rate, novelty = analysis.rate, analysis.novelty
    short = analysis.short_novelty(p["min_segment_s"])
    tops, props = find_peaks(np.concatenate([[0.0], short, [0.0]]), prominence=0.0)
    tops, prominence = tops - 1, props["prominences"]
    reach = p["scale_min_s"] * rate
    inside = np.abs(tops[:, None] - peaks[None, :]).min(axis=1) > reach / 2
    if not inside.any():
        return peaks, strength
    level = max(p["short_activity"] * float(np.median(prominence[inside])), p["prominence"])
    strong = tops[prominence >= level]
    tolerance = SHORT_PEAK_TOLERANCE_S * rate
    distance = p["min_segment_s"] * rate

    def confirmed(sample: int) -> int | None:
        if not len(strong):
            return None
        best = strong[np.argmin(np.abs(strong - sample))]
        return int(best) if abs(best - sample) <= tolerance else None

    shoulders, _ = find_peaks(np.concatenate([[0.0], novelty, [0.0]]),
                              height=max(p["threshold"], 1e-12))
    cuts = list(peaks)
    for shoulder in shoulders - 1:
        kept = int(peaks[np.argmin(np.abs(peaks - shoulder))])
        if np.abs(np.asarray(cuts) - shoulder).min() < distance or \
                abs(shoulder - kept) > reach or confirmed(kept) is None:
            continue
        side = confirmed(shoulder)
        if side is None or np.abs(np.asarray(cuts) - side).min() < distance:
            continue
        if p["short_uniformity"] > 0 and not (
                mixing(analysis, kept, side, int(round(distance))) <= p["short_uniformity"]):
            continue
        cuts.append(side)
    added = np.asarray(cuts[len(peaks):], dtype=np.int64)
    order = np.argsort(np.concatenate([peaks, added]), kind="stable")
    evidence = np.concatenate([strength, np.full(len(added), p["prominence"])])
    return np.concatenate([peaks, added])[order], evidence[order]


def mixing(analysis: Analysis, a: int, b: int, context: int) -> float:
    """How unlike itself the stretch between novelty samples ``a`` and ``b`` is.

    MMD² between the stretch's two halves over MMD² between the stretch and the nearer-
    looking of its neighbours (``context`` samples each side), on the novelty blocks and
    kernel. An activity repeats, so its halves look alike (near 0); the passage from one
    activity into the next morphs, so its halves differ about as much as it differs from
    its neighbours (near 1 and above). NaN when a part is too short to compare.
    """
    lo, hi = sorted((a, b))
    blocks = analysis.blocks
    middle, before, after = blocks[lo:hi], blocks[max(0, lo - context):lo], blocks[hi:hi + context]
    if len(middle) < 4 or min(len(before), len(after)) < 2:
        return float("nan")
    half = len(middle) // 2
    inner = mmd(middle[:half], middle[half:], analysis.gamma)
    return inner / max(min(mmd(before, middle, analysis.gamma),
                           mmd(middle, after, analysis.gamma)), 1e-12)


def mmd(x: np.ndarray, y: np.ndarray, gamma: float) -> float:
    """Biased MMD² between the samples ``x`` (n, d) and ``y`` (m, d), Gaussian kernel."""
    def mean_k(u, v):
        return float(np.exp(-gamma * cdist(u, v, "sqeuclidean")).mean())
    return mean_k(x, x) + mean_k(y, y) - 2 * mean_k(x, y)
