"""Probabilistic-PCA segmentation (Barbič et al. 2004, "Segmenting motion capture data
into distinct behaviors"), the 2011 paper's baseline.

A Gaussian with a probabilistic-PCA covariance (r principal directions plus isotropic
noise σ², the mean of the discarded eigenvalues) is fitted to the frames of the current
segment so far, ``[start, K)``. The average Mahalanobis distance H(K) of the next
``window_s`` of frames to that model is tracked as K grows in steps of ``step_s``; a
new behaviour makes H jump. A cut is declared where the jump ``d = H(K) - H(K - step)``
exceeds the mean of the earlier jumps in this segment by ``r_std`` standard deviations
(the paper's R = 3), at the largest jump of that excursion; the search restarts there.

The intrinsic dimension r is the smallest number of principal directions of the first
window of each segment that explain ``tau`` of its variance (the paper fixes r per
motion from such an energy fraction).

Deviation, stated: the paper represents a pose by joint-rotation quaternions; this
implementation uses joint positions in the body frame (relative to the root, heading
removed, ``features.body_frame_positions``), which are likewise smooth and do not
change when the performer walks or turns.
"""

from __future__ import annotations

import time

import numpy as np

from motionlib import features
from motionlib.segmenters.base import Param, Segmentation, Segmenter, full_length, take_positions


class PPCAModel:
    """A probabilistic-PCA Gaussian from a mean (d,) and covariance (d, d)."""

    def __init__(self, mean: np.ndarray, cov: np.ndarray, r: int) -> None:
        self.mean = mean
        values, vectors = np.linalg.eigh(cov)
        values, vectors = values[::-1], vectors[:, ::-1]
        r = min(r, len(values) - 1)
        sigma2 = max(float(values[r:].mean()), 1e-9 * max(float(values[0]), 1e-12), 1e-12)
        self.variances = np.concatenate([np.maximum(values[:r], sigma2), [sigma2]])
        self.vectors = vectors[:, :r]

    @classmethod
    def fit(cls, x: np.ndarray, r: int) -> PPCAModel:
        return cls(x.mean(axis=0), np.cov(x, rowvar=False, bias=True), r)

    def mahalanobis(self, x: np.ndarray) -> np.ndarray:
        """Squared Mahalanobis distance of each row of ``x`` (n, d) -> (n,)."""
        centred = x - self.mean
        proj = centred @ self.vectors
        residual = (centred * centred).sum(axis=1) - (proj * proj).sum(axis=1)
        return (proj**2 / self.variances[:-1]).sum(axis=1) + residual / self.variances[-1]


def intrinsic_dimension(x: np.ndarray, tau: float) -> int:
    """Smallest r whose principal directions explain ``tau`` of the variance of ``x``."""
    values = np.linalg.eigvalsh(np.cov(x, rowvar=False, bias=True))[::-1]
    energy = np.cumsum(np.maximum(values, 0)) / max(values.clip(0).sum(), 1e-300)
    return int(np.searchsorted(energy, tau) + 1)


def next_cut(
    x: np.ndarray, start: int, *, window: int, step: int, r_std: float, tau: float
) -> tuple[int | None, float, list[tuple[int, float]]]:
    """Scan from ``start``; return (cut frame or None, its jump z-score, H curve points)."""
    r = intrinsic_dimension(x[start : start + window], tau)
    history: list[float] = []
    curve: list[tuple[int, float]] = []
    prev = None
    best: tuple[int, float] | None = None
    # Running sums keep each step O(step d²) instead of refitting on all frames.
    total = x[start : start + window].sum(axis=0)
    scatter = x[start : start + window].T @ x[start : start + window]
    for k in range(start + window, len(x) - window + 1, step):
        if k > start + window:
            new = x[k - step : k]
            total += new.sum(axis=0)
            scatter += new.T @ new
        n = k - start
        mean = total / n
        model = PPCAModel(mean, scatter / n - np.outer(mean, mean), r)
        h = float(model.mahalanobis(x[k : k + window]).mean())
        curve.append((k, h))
        if prev is not None:
            d = h - prev
            if len(history) >= 5:
                z = (d - np.mean(history)) / max(np.std(history), 1e-12)
                if z > r_std:
                    best = (k, z) if best is None or z > best[1] else best
                elif best is not None:
                    return best[0], best[1], curve  # the excursion ended: cut at its peak
            history.append(d)
        prev = h
    return (best[0], best[1], curve) if best else (None, 0.0, curve)


class PPCA(Segmenter):
    name = "ppca"
    title = "Probabilistic PCA (Barbič et al. 2004)"
    description = (
        "Fits a probabilistic-PCA Gaussian to the segment so far and cuts where the "
        "Mahalanobis distance of the next frames jumps by more than R standard deviations."
    )
    params = {
        "window_s": Param("float", 1.25, 0.1, 60.0, "Frames T tested ahead (s); paper: 150."),
        "step_s": Param("float", 1 / 12, 0.005, 10.0, "Growth step Δ of K (s); paper: 10."),
        "r_std": Param("float", 3.0, 0.0, 100.0, "Jump threshold R in standard deviations."),
        "tau": Param("float", 0.9, 0.1, 1.0, "Variance fraction fixing the dimension r."),
    }

    def _segment(self, take, *, window_s, step_s, r_std, tau) -> Segmentation:
        t0 = time.perf_counter()
        positions, joints, first = take_positions(take)
        t1 = time.perf_counter()
        x = features.body_frame_positions(positions, joints).reshape(len(positions), -1)
        window = max(2, int(round(window_s * take.fps)))
        step = max(1, int(round(step_s * take.fps)))
        cuts, scores, curve = [], [], np.full(len(x), np.nan)
        start = 0
        while start + 2 * window <= len(x):
            cut, z, points = next_cut(x, start, window=window, step=step, r_std=r_std, tau=tau)
            for k, h in points:
                curve[k] = h
            if cut is None:
                break
            cuts.append(cut)
            scores.append(z)
            start = cut
        t2 = time.perf_counter()
        signal = _fill_gaps(curve)
        z = np.asarray(scores, dtype=float)
        return Segmentation(
            cuts=np.asarray(cuts, dtype=np.int64) + first,
            confidence=z / (z + r_std) if len(z) else z,
            signals={"mahalanobis": full_length(signal, first)},
            timings={"kinematics": t1 - t0, "detect": t2 - t1},
        )


def _fill_gaps(curve: np.ndarray) -> np.ndarray:
    """Linear interpolation over NaN samples (0 where nothing was computed)."""
    known = np.flatnonzero(np.isfinite(curve))
    if len(known) == 0:
        return np.zeros(len(curve))
    return np.interp(np.arange(len(curve)), known, curve[known])
