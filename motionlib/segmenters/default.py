"""Cutroom's own detector: multi-scale kernel novelty on a heading-invariant pose.

Why this design
---------------
An activity in a take (jumping jacks, squats, walking) is a *distribution* of poses that
repeats every second or so; a boundary is where that distribution changes. So:

1. Each frame becomes a pose vector that ignores where the performer stands and which
   way they face (joint positions relative to the root, heading removed, plus the root
   height, which separates squatting and jumping from standing), optionally with joint
   velocities so that holding a pose differs from moving through it.
2. The pose stream is averaged into short blocks (``rate_hz``) for speed.
3. At each instant the poses of the past window and the future window are compared
   with the maximum mean discrepancy (MMD) under a Gaussian kernel whose bandwidth is
   set by the median heuristic, at three window lengths from ``scale_min_s`` to
   ``scale_max_s`` (3 to 6 s: a window must span several repetitions of a periodic
   activity, about 1 Hz for most exercises, so that the poses inside one activity look
   alike from window to window; shorter windows also fire on brief changes inside an
   activity that annotators do not cut). MMD² is 0 for identical distributions and
   approaches 2 for disjoint ones, whatever the capture's units.
4. Peaks of the mean novelty curve higher than ``threshold`` and at least
   ``min_segment_s`` apart become cuts; confidence ``s / (s + threshold)`` grows with
   the peak height s (0.5 at the threshold), so candidates rank by evidence.
5. Placement, coarse to fine. The novelty peak locates a change only to within a
   block and a window; an annotator cuts at "the moment the motion changes": the end
   of the last movement of the old activity, where the body is momentarily still.
   So each cut is re-estimated in three steps, all at most ``refine_s`` from the
   previous estimate:

   a. *Split.* Over ``±scale_min_s`` around the peak (never past half-way to a
      neighbouring cut), the split that minimises the within-segment variance of the
      poses in the kernel's feature space (the kernel change-point cost, same kernel as
      the novelty) on 30 Hz block means: the best two-segment fit of that stretch.
   b. *Turning point.* The cut moves to the nearest local minimum of the pose speed
      (poses low-passed at 3 Hz, native frame rate): the split locates the change to
      within a movement cycle, and between two cycles the body turns.
   c. *Pause.* If the performer really stops nearby (the 1 Hz speed falls below half
      its typical value around the cut), the cut moves to that pause, where
      annotators cut too (``settle_frame``).

   Tried on the three labelled CMU takes (mean of the per-take median cut errors; it
   was 0.23 s with the peak moved only to a pause) and on synthetic takes, choosing
   only between these principled settings, with no per-take or per-count knowledge:
   the split alone (a) places synthetic cuts within 0.05 s (their truth is the
   middle of a cross-fade, a statistical midpoint) but real ones 0.24 s off, because
   annotators cut between movements, not at the midpoint of the statistics; (a)+(b)
   takes the real error to 0.09 s; (c) then fixes one more real cut (fewer edits,
   same median). On synthetic takes (10 seeds at 120, 60 and 30 fps) F1 is unchanged
   and the median error stays about where it was (0.22 -> 0.24 s): there the turning
   point lies up to a quarter cycle from the cross-fade's middle. Not kept: the
   turning point with the best split statistic instead of the nearest (0.19 s),
   joint velocities in the split statistic (no gain), a linear (mean-pose) cost
   instead of the kernel (0.54 s: periodic activities share a mean pose), a context
   of ``scale_max_s`` instead of ``scale_min_s`` (same or worse), and the native
   frame rate for the split (same result, several times the time).

All durations are in seconds, so the same defaults work at any frame rate.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.signal import find_peaks
from scipy.spatial.distance import cdist

from motionlib import features
from motionlib.segmenters.base import (
    Param,
    ParamError,
    Segmentation,
    Segmenter,
    full_length,
    take_positions,
)

POSE_JOINTS = (
    "head", "chest", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
    "left_knee", "right_knee", "left_ankle", "right_ankle",
)


def pose_features(
    positions: np.ndarray, joints: dict[str, int], *, fps: float, velocity_s: float
) -> np.ndarray:
    """Heading-invariant pose vectors.

    Returns
    -------
    (n_frames, n_features): body-frame positions of ``POSE_JOINTS``, root height
    (minus its median) and, when ``velocity_s > 0``, their velocities times
    ``velocity_s`` seconds (a length, so both parts share one unit).
    """
    body = features.body_frame_positions(positions, joints, [joints[j] for j in POSE_JOINTS])
    pose = body.reshape(len(positions), -1)
    height = positions[:, joints["root"], 1:2]
    x = np.concatenate([pose, height - np.median(height)], axis=1)
    if velocity_s > 0:
        smooth = features.lowpass(x, fps=fps, cutoff_hz=min(3.0, 0.45 * fps))
        x = np.concatenate([x, np.gradient(smooth, axis=0) * fps * velocity_s], axis=1)
    return x


def block_mean(x: np.ndarray, step: int) -> np.ndarray:
    """Average consecutive blocks of ``step`` frames: (n, d) -> (n // step, d)."""
    n = len(x) // step
    return x[: n * step].reshape(n, step, -1).mean(axis=1)


def median_sq_distance(x: np.ndarray, max_points: int = 1000) -> float:
    """Median squared distance between rows (on an even subsample for long inputs)."""
    sub = x[:: max(1, len(x) // max_points)]
    sq = (sub * sub).sum(axis=1)
    d2 = sq[:, None] + sq[None, :] - 2 * sub @ sub.T
    return float(np.median(d2[np.triu_indices(len(sub), 1)]))


def mmd_novelty(x: np.ndarray, w: int, gamma: float) -> np.ndarray:
    """MMD² between the ``w`` samples before and the ``w`` samples from each instant.

    Only kernel values at lags below ``2 w`` are needed, so memory and time are
    O(n w) rather than O(n²), which keeps hour-long takes cheap.

    Parameters
    ----------
    x : (n, d) samples; w : window length in samples; gamma : kernel 1 / bandwidth².

    Returns
    -------
    (n,) biased MMD² estimate at each split t (0 where a window would leave the take).
    """
    n = len(x)
    out = np.zeros(n)
    if n < 2 * w or w < 1:
        return out
    t = np.arange(w, n - w + 1)
    within = np.zeros(len(t))
    cross = np.zeros(len(t))
    for lag in range(0, 2 * w):
        k = np.exp(-gamma * ((x[lag:] - x[: n - lag]) ** 2).sum(axis=1))
        c = np.concatenate([[0.0], np.cumsum(k)])  # c[i] = sum of k[:i]
        if lag < w:  # pairs (i, i + lag) inside the past and inside the future window
            mult = 1.0 if lag == 0 else 2.0
            within += mult * (c[t - lag] - c[t - w] + c[t + w - lag] - c[t])
        if lag >= 1:  # pairs with i in the past window and i + lag in the future one
            lo = np.maximum(t - w, t - lag)
            hi = np.minimum(t, t + w - lag)
            cross += np.where(hi > lo, c[np.maximum(hi, lo)] - c[lo], 0.0)
    out[t] = (within - 2 * cross) / (w * w)
    return np.maximum(out, 0.0)


def mirrored_novelty(x: np.ndarray, w: int, gamma: float) -> np.ndarray:
    """``mmd_novelty`` with the take mirrored at both ends.

    Mirroring lets a window that would run off the take see the nearest real poses
    again, so an activity shorter than a window at the very start or end still
    produces a peak at its boundary.
    """
    w = min(w, len(x) - 1)
    if w < 1:
        return np.zeros(len(x))
    padded = np.concatenate([x[w:0:-1], x, x[-2 : -w - 2 : -1]])
    return mmd_novelty(padded, w, gamma)[w : w + len(x)]


# A pause is a slowest frame at most this fraction of the typical speed around it.
PAUSE_RATIO = 0.5


def settle_frame(speed: np.ndarray, cut: int, radius: int, context: int) -> int:
    """Move ``cut`` to a pause within ``radius`` frames, if there is one.

    Performers often stop briefly between two activities and annotators cut there. The
    slowest frame near the cut counts as such a pause only when it is well below the
    median speed over ``±context`` frames: every periodic movement slows down at its
    turning points, and those must not pull a cut away from the statistical change.
    """
    a, b = max(1, cut - radius), min(len(speed) - 1, cut + radius + 1)
    if b <= a:
        return cut
    slowest = a + int(np.argmin(speed[a:b]))
    typical = np.median(speed[max(0, cut - context) : cut + context])
    return slowest if speed[slowest] < PAUSE_RATIO * typical else cut


def split_gains(x: np.ndarray, gamma: float) -> np.ndarray:
    """How well each split cuts ``x`` into two homogeneous segments.

    With the Gaussian kernel k, the within-segment variance of a split at t in the
    kernel's feature space is ``n - S(0, t) / t - S(t, n) / (n - t)``, where S(a, b) sums
    k over all pairs in ``x[a:b]`` (the kernel change-point cost). Its constant part
    dropped, the best split has the largest gain ``S(0, t) / t + S(t, n) / (n - t)``.

    Parameters
    ----------
    x : (n, d) samples; gamma : kernel 1 / bandwidth².

    Returns
    -------
    (n - 1,) gains of the splits t = 1 .. n - 1 (empty when n < 2).
    """
    n = len(x)
    # cdist rather than a matrix product: threaded BLAS on matrices this small costs
    # more in thread hand-offs than the arithmetic on a busy machine.
    k = np.exp(-gamma * cdist(x, x, "sqeuclidean"))
    c = np.zeros((n + 1, n + 1))
    c[1:, 1:] = k.cumsum(axis=0).cumsum(axis=1)  # c[a, b] = sum of k[:a, :b]
    t = np.arange(1, n)
    right = c[n, n] - 2 * c[t, n] + c[t, t]  # k is symmetric: c[t, n] == c[n, t]
    return c[t, t] / t + right / (n - t)


def best_split(x: np.ndarray, cut: int, lo: int, hi: int, *, step: int, radius: int,
               gamma: float) -> int:
    """The frame within ``radius`` of ``cut`` that best splits ``x[lo:hi]`` in two.

    ``x`` is averaged into blocks of ``step`` frames first, so the split is found to
    within one block; ``cut`` itself is returned when no block boundary is in reach.
    """
    if hi - lo < 2 * step:  # not two blocks: nothing to split
        return cut
    blocks = block_mean(x[lo:hi], step)
    frames = lo + step * np.arange(1, len(blocks))
    near = np.abs(frames - cut) <= radius
    if not near.any():
        return cut
    gains = split_gains(blocks, gamma)
    return int(frames[near][np.argmax(gains[near])])


def turning_points(x: np.ndarray, *, fps: float) -> np.ndarray:
    """Frames where the pose momentarily slows down (local minima of its speed).

    The poses are low-passed at 3 Hz first, as for the velocities, so that capture
    jitter does not make turning points of its own.

    Returns
    -------
    (n_points,) int frames, increasing.
    """
    smooth = features.lowpass(x, fps=fps, cutoff_hz=min(3.0, 0.45 * fps))
    frames, is_max = features.local_extrema(features.frame_speed(smooth, fps=fps))
    return frames[~is_max]


def nearest(points: np.ndarray, target: int, radius: int) -> int:
    """The point nearest ``target`` if one is within ``radius``, else ``target``."""
    if len(points) == 0:
        return target
    best = points[np.argmin(np.abs(points - target))]
    return int(best) if abs(best - target) <= radius else target


# The split is searched on block means at this rate: finer than the 0.1 s that
# annotators label at, and the cut then moves to a turning point at the native rate.
SPLIT_RATE_HZ = 30.0
# Poses in the longest comparison window (rate_hz * scale_max_s); the cost of a take
# grows with its square.
MAX_WINDOW_SAMPLES = 600


class Default(Segmenter):
    name = "default"
    title = "Cutroom default (multi-scale kernel novelty)"
    description = (
        "Compares the distribution of heading-invariant poses before and after each "
        "instant (kernel MMD at 3-6 s windows); strong peaks become cuts, placed at the "
        "best two-segment split, then at the nearest turning point or pause of the "
        "motion. Parameters are in seconds and work at any frame rate."
    )
    params = {
        "threshold": Param(
            "float", 0.25, 0.0, 2.0,
            "Minimum mean MMD² (0 = same poses, 2 = disjoint) for a peak to become a cut.",
        ),
        "min_segment_s": Param("float", 2.0, 0.1, 60.0, "Minimum time between two cuts (s)."),
        # Cost grows with the square of the samples in a window (rate_hz * scale_max_s,
        # at most MAX_WINDOW_SAMPLES): the bounds keep a one-hour take within minutes.
        "scale_min_s": Param("float", 3.0, 0.2, 20.0, "Shortest comparison window (s)."),
        "scale_max_s": Param("float", 6.0, 0.2, 20.0, "Longest comparison window (s)."),
        "bandwidth": Param(
            "float", 0.3, 0.01, 100.0,
            "Kernel width² as a multiple of the median squared pose distance.",
        ),
        "velocity_s": Param(
            "float", 0.0, 0.0, 5.0,
            "Weight (s) of joint velocities beside the poses; 0 compares poses only.",
        ),
        "refine_s": Param(
            "float", 0.5, 0.0, 5.0,
            "How far (s) each placement step (best split, turning point, pause) may move a cut.",
        ),
        "rate_hz": Param("float", 10.0, 1.0, 60.0, "Pose rate (Hz) for the novelty curve."),
    }

    @classmethod
    def validate_params(cls, values):
        p = super().validate_params(values)
        if p["rate_hz"] * p["scale_max_s"] > MAX_WINDOW_SAMPLES:
            raise ParamError(
                f"rate_hz: rate_hz * scale_max_s must be at most {MAX_WINDOW_SAMPLES} poses "
                f"per window, got {p['rate_hz']:g} * {p['scale_max_s']:g}"
            )
        return p

    def _segment(self, take, **p) -> Segmentation:
        if p["scale_max_s"] < p["scale_min_s"]:
            raise ParamError(
                f"scale_max_s: must be at least scale_min_s ({p['scale_min_s']:g}), "
                f"got {p['scale_max_s']:g}"
            )
        fps = float(take.fps)
        t0 = time.perf_counter()
        positions, joints, first = take_positions(take)
        t1 = time.perf_counter()
        x = pose_features(positions, joints, fps=fps, velocity_s=p["velocity_s"])
        step = max(1, int(round(fps / p["rate_hz"])))
        if len(x) < 2 * step:  # too short to compare anything: no cuts
            flat = full_length(np.zeros(len(x)), first)
            return Segmentation(np.zeros(0, np.int64), np.zeros(0), {"novelty": flat})
        blocks = block_mean(x, step)
        # One kernel for detection and placement, its width from the median heuristic.
        gamma = 1.0 / max(p["bandwidth"] * median_sq_distance(blocks), 1e-12)
        novelty = self._novelty(blocks, fps / step, gamma, p)
        t2 = time.perf_counter()
        peaks, strength = self._peaks(novelty, fps / step, p)
        cuts, speed = self._place(x, peaks * step + step // 2, fps, gamma, p)
        t3 = time.perf_counter()
        centres = np.arange(len(novelty)) * step + step / 2
        curve = np.interp(np.arange(len(x)), centres, novelty)
        return Segmentation(
            cuts=cuts + first,
            confidence=strength / (strength + p["threshold"] + 1e-12),
            signals={"novelty": full_length(curve, first), "speed": full_length(speed, first)},
            timings={"kinematics": t1 - t0, "novelty": t2 - t1, "cuts": t3 - t2},
        )

    @staticmethod
    def _place(x: np.ndarray, peaks: np.ndarray, fps: float, gamma: float, p: dict):
        """Re-estimate each cut: best split, nearest turning point, nearby pause.

        Returns the placed cuts (frames of ``x``) and the 1 Hz pose speed.
        """
        speed = features.lowpass(features.frame_speed(x, fps=fps), fps=fps, cutoff_hz=1.0)
        step = max(1, int(round(fps / SPLIT_RATE_HZ)))
        turns = turning_points(x, fps=fps)
        radius = int(round(p["refine_s"] * fps))
        context = int(round(p["scale_min_s"] * fps))
        placed = []
        for i, cut in enumerate(int(c) for c in peaks):
            # Never look past half-way to a neighbouring cut: that stretch is theirs.
            lo = max(0, cut - context, (int(peaks[i - 1]) + cut) // 2 if i else 0)
            hi = min(len(x), cut + context)
            if i + 1 < len(peaks):
                hi = min(hi, (cut + int(peaks[i + 1])) // 2)
            split = best_split(x, cut, lo, hi, step=step, radius=radius, gamma=gamma)
            turn = nearest(turns, split, radius)
            placed.append(settle_frame(speed, turn, radius, context))
        return np.asarray(placed, dtype=np.int64), speed

    @staticmethod
    def _novelty(x: np.ndarray, rate: float, gamma: float, p: dict) -> np.ndarray:
        """Mean MMD² over window lengths evenly spread between the two scales."""
        if len(x) < 4:
            return np.zeros(len(x))
        scales = np.linspace(p["scale_min_s"], p["scale_max_s"], 3)
        widths = sorted({max(1, int(round(s * rate))) for s in scales})
        return np.mean([mirrored_novelty(x, w, gamma) for w in widths], axis=0)

    @staticmethod
    def _peaks(novelty: np.ndarray, rate: float, p: dict) -> tuple[np.ndarray, np.ndarray]:
        # Zero guards let a peak sit on the first or last sample.
        padded = np.concatenate([[0.0], novelty, [0.0]])
        distance = max(1, int(round(p["min_segment_s"] * rate)))
        peaks, _ = find_peaks(padded, height=max(p["threshold"], 1e-12), distance=distance)
        peaks = peaks - 1
        # The first and last segment may be shorter than the others, but not absurdly:
        # at least half the minimum segment.
        edge = p["min_segment_s"] * rate / 2
        peaks = peaks[(peaks + 0.5 >= edge) & (len(novelty) - peaks - 0.5 >= edge)]
        return peaks, novelty[peaks]
