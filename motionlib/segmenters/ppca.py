"""Probabilistic-PCA segmentation (Barbič et al. 2004, "Segmenting motion capture data
into distinct behaviors"), the 2011 paper's baseline.

A Gaussian with a probabilistic-PCA covariance (r principal directions plus isotropic
noise σ², the mean of the discarded eigenvalues) is fitted to the frames of the current
segment so far, ``[start, K)``. The average Mahalanobis distance H(K) of the next
``window_s`` of frames to that model is tracked as K grows in steps of ``step_s``; a
new behaviour makes H jump. A boundary is detected where the jump
``d = H(K) - H(K - step)`` exceeds the mean of the earlier jumps in this segment by
``r_std`` standard deviations (the paper's R = 3); the cut is placed at the maximum of H
within one window after that (H peaks when the tested frames are all new, i.e. at the
boundary), and the search restarts there.

The intrinsic dimension r is the smallest number of principal directions of the first
window of each segment that explain ``tau`` of its variance (the paper fixes r per
motion from such an energy fraction).

Deviations, stated:

- The jump statistics are the median and the scaled median absolute deviation of the
  earlier jumps instead of their mean and standard deviation. With the mean and
  standard deviation, the large swings of H in the first window of a segment (the model
  is fitted to barely one window of frames) inflate the deviation so much that no later
  boundary ever stands out; on the labelled CMU takes the literal rule finds one cut in
  fifteen. The evident intent, "a jump unusual for this segment", is kept.
- The paper represents a pose by joint-rotation quaternions; this implementation uses
  joint positions in the body frame (relative to the root, heading removed,
  ``features.body_frame_positions``) of the 18 canonical joints other than the root
  (54 numbers, close to the paper's 56), which are likewise smooth and do not change
  when the performer walks or turns. Points of no known marker set (no body parts) are
  described by their coordinates, gaps closed.
"""

from __future__ import annotations

import time

import numpy as np

from motionlib import features
from motionlib.points import bare_coordinates, is_point_take
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


def distance_curve(x: np.ndarray, start: int, *, window: int, step: int, r: int):
    """Yield (K, H(K)) for K = start + window, start + window + step, ...

    H(K) is the mean squared Mahalanobis distance of frames ``[K, K + window)`` to the
    PPCA model of frames ``[start, K)``. Running sums keep each step O(step d²).
    """
    total = x[start : start + window].sum(axis=0)
    scatter = x[start : start + window].T @ x[start : start + window]
    for k in range(start + window, len(x) - window + 1, step):
        if k > start + window:
            new = x[k - step : k]
            total += new.sum(axis=0)
            scatter += new.T @ new
        mean = total / (k - start)
        model = PPCAModel(mean, scatter / (k - start) - np.outer(mean, mean), r)
        yield k, float(model.mahalanobis(x[k : k + window]).mean())


def next_cut(
    x: np.ndarray, start: int, *, window: int, step: int, r_std: float, tau: float
) -> tuple[int | None, float, list[tuple[int, float]]]:
    """Scan from ``start`` for the next cut.

    Returns
    -------
    cut : frame of the cut, or None when the take ends first.
    z : the triggering jump in standard deviations of the earlier jumps.
    curve : the (K, H) points computed.
    """
    r = intrinsic_dimension(x[start : start + window], tau)
    jumps: list[float] = []
    curve: list[tuple[int, float]] = []
    trigger, z = None, 0.0
    for k, h in distance_curve(x, start, window=window, step=step, r=r):
        curve.append((k, h))
        if trigger is not None:
            if k > trigger + window:
                break
            continue
        if len(curve) > 1:
            d = h - curve[-2][1]
            if len(jumps) >= 5:
                centre = float(np.median(jumps))
                spread = 1.4826 * float(np.median(np.abs(np.asarray(jumps) - centre)))
                z = (d - centre) / max(spread, 1e-12)
                if z > r_std:
                    trigger = k
            jumps.append(d)
    if trigger is None:
        return None, 0.0, curve
    # H rises while the tested frames fill with the new behaviour and is largest when
    # they are all new, i.e. when K reaches the boundary: cut at that maximum.
    after = [(h, k) for k, h in curve if k >= trigger]
    return max(after)[1], z, curve


class PPCA(Segmenter):
    name = "ppca"
    title = "Probabilistic PCA (Barbič et al. 2004)"
    description = (
        "Fits a probabilistic-PCA Gaussian to the segment so far and cuts where the "
        "Mahalanobis distance of the next frames jumps by more than R standard deviations."
    )
    params = {
        # Cost grows with window_s and with 1 / step_s; the bounds keep a one-hour take
        # within a few minutes of CPU (CUTROOM_DETECT_TIME_LIMIT).
        "window_s": Param("float", 1.25, 0.1, 10.0, "Frames T tested ahead (s); paper: 150."),
        "step_s": Param("float", 1 / 12, 0.04, 10.0, "Growth step Δ of K (s); paper: 10."),
        "r_std": Param("float", 3.0, 0.0, 100.0, "Jump threshold R in standard deviations."),
        "tau": Param("float", 0.9, 0.1, 1.0, "Variance fraction fixing the dimension r."),
    }

    def _segment(self, take, *, window_s, step_s, r_std, tau) -> Segmentation:
        t0 = time.perf_counter()
        x, first = pose_vectors(take)
        t1 = time.perf_counter()
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


def pose_vectors(take) -> tuple[np.ndarray, int]:
    """Per-frame pose vectors (n_used, d) and the take frame of the first: the body-frame
    positions of the canonical joints other than the root, or for points of no known marker
    set their coordinates (``points.bare_coordinates``)."""
    if is_point_take(take) and take.marker_set is None:
        return bare_coordinates(take), 0
    positions, joints, first = take_positions(take)
    named = [index for name, index in sorted(joints.items()) if name != "root"]
    return features.body_frame_positions(positions, joints, named).reshape(len(positions), -1), first


def _fill_gaps(curve: np.ndarray) -> np.ndarray:
    """Linear interpolation over NaN samples (0 where nothing was computed)."""
    known = np.flatnonzero(np.isfinite(curve))
    if len(known) == 0:
        return np.zeros(len(curve))
    return np.interp(np.arange(len(curve)), known, curve[known])
