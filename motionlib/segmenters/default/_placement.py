"""Stage 5 of the default detector: where each cut goes, coarse to fine.

A novelty peak locates a change only to within a block and a window; annotators cut at
the moment the motion changes: the end of the last movement of the old activity, where
the body is momentarily still, or, after a pause, where the next activity sets off. So
each cut is re-estimated in four steps (``PLACEMENTS``), the first three at most
``refine_s`` from the previous estimate: the best two-segment kernel split of the poses
around the peak (never past half-way to a neighbouring cut), the nearest turning point
of the pose speed, a nearby pause, and the onset of the next activity after a pause of
at most 3 s (``onset``). ``docs/detector/placement.md`` says how each step was chosen.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlib import features
from motionlib.segmenters.default._features import block_mean
from motionlib.segmenters.default._novelty import sq_distances

# The split is searched on block means at this rate: finer than the 0.1 s that
# annotators label at, and the cut then moves to a turning point at the native rate.
SPLIT_RATE_HZ = 30.0

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


# How far (s) the onset of the next activity may lie after a pause.
ONSET_MAX_S = 3.0


def onset_frame(speed: np.ndarray, cut: int, stop: int, context: int) -> int:
    """The end of the pause ``cut`` lies in: where the next activity sets off.

    When the speed at ``cut`` is below ``PAUSE_RATIO`` of the median speed over
    ``±context`` frames, the performer may be standing between two activities, and
    annotators who cut at the onset of the next one cut where the speed rises past that
    level again. Only a pause that ends by frame ``stop``, lasts at most ``stop - cut``
    frames in all and is followed by ``context`` frames at the typical speed (and at
    least half the speed of the ``context`` frames before) counts: a
    longer slow stretch, or one followed by slow motion, is an activity of its own
    (standing, idling), not a pause between two. Elsewhere ``cut`` is returned unchanged.
    """
    level = PAUSE_RATIO * np.median(speed[max(0, cut - context) : cut + context])
    if not speed[cut] < level or stop <= cut:
        return cut
    above = np.flatnonzero(speed[cut : stop + 1] >= level)
    if not len(above):
        return cut
    end = cut + int(above[0])
    before = np.flatnonzero(speed[max(0, end - (stop - cut)) : cut] >= level)
    # The next activity must then move at least at the typical speed and at half the
    # previous one's: a slow one (idling, swaying) is not set off by a rise of a moment.
    after = np.median(speed[end : end + context])
    moving = after >= max(level / PAUSE_RATIO,
                          PAUSE_RATIO * np.median(speed[max(0, cut - context) : cut]))
    return end if len(before) and moving else cut


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
    k = np.exp(-gamma * sq_distances(x))
    # With c[a, b] the sum of k[:a, :b] and k symmetric: c[t, n] sums the first t rows,
    # and c[t, t] adds, row by row, the diagonal entry and twice the entries left of it.
    rows = np.cumsum(k.sum(axis=1))  # c[t, n] for t = 1 .. n
    square = np.cumsum(2 * np.tril(k, -1).sum(axis=1) + k.diagonal())  # c[t, t]
    t = np.arange(1, n)
    inside, before = square[:-1], rows[:-1]
    right = square[-1] - 2 * before + inside
    return inside / t + right / (n - t)


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


def fine_speed(x: np.ndarray, *, fps: float) -> np.ndarray:
    """Pose speed per frame with the poses low-passed at 3 Hz first, as for the
    velocities, so that capture jitter makes no turning points or onsets of its own."""
    smooth = features.lowpass(x, fps=fps, cutoff_hz=min(3.0, 0.45 * fps))
    return features.frame_speed(smooth, fps=fps)


def turning_points(x: np.ndarray, *, fps: float) -> np.ndarray:
    """Frames where the pose momentarily slows down (local minima of ``fine_speed``).

    Returns
    -------
    (n_points,) int frames, increasing.
    """
    return speed_minima(fine_speed(x, fps=fps))


def speed_minima(speed: np.ndarray) -> np.ndarray:
    """The frames of the local minima of ``speed``: the turning points when it is
    ``fine_speed`` (already computed, as ``pose_speeds`` gives it)."""
    frames, is_max = features.local_extrema(speed)
    return frames[~is_max]


def nearest(points: np.ndarray, target: int, radius: int) -> int:
    """The point nearest ``target`` if one is within ``radius``, else ``target``."""
    if len(points) == 0:
        return target
    best = points[np.argmin(np.abs(points - target))]
    return int(best) if abs(best - target) <= radius else target


PLACEMENTS = ("split", "turn", "pause", "onset")


def shipped_stage(p: dict) -> str:
    """The placement step (of ``PLACEMENTS``) whose estimate the detector cuts at:
    ``onset`` with ``p["onset"]``, else ``pause``."""
    return "onset" if p["onset"] else "pause"


def pose_speeds(x: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """The two pose speeds placement reads: low-passed at 1 Hz (pauses) and the speed of
    the poses low-passed at 3 Hz (``fine_speed``: turning points, onsets)."""
    speed = features.lowpass(features.frame_speed(x, fps=fps), fps=fps, cutoff_hz=1.0)
    return speed, fine_speed(x, fps=fps)


def place_stages(x: np.ndarray, peaks: np.ndarray, fps: float, gamma: float, p: dict,
                 speeds: tuple[np.ndarray, np.ndarray] | None = None,
                 only: np.ndarray | None = None):
    """Each placement step's estimate of every cut (see the module docstring).

    ``speeds``: ``pose_speeds(x, fps)`` when already computed (tuning places many sets
    of peaks on one take). ``only``: (n_cuts,) bool, place only these cuts (each still
    bounded by all its neighbours); the others' estimates are their own frame.

    Returns
    -------
    stages : {"split", "turn", "pause", "onset"} -> (n_cuts,) int frames of ``x``, each
        step starting from the previous one's result.
    speed : (n,) the 1 Hz pose speed.
    """
    speed, fine = pose_speeds(x, fps) if speeds is None else speeds
    step = max(1, int(round(fps / SPLIT_RATE_HZ)))
    turns = speed_minima(fine)
    radius = int(round(p["refine_s"] * fps))
    context = int(round(p["scale_min_s"] * fps))
    onset_radius = int(round(ONSET_MAX_S * fps))
    stages = {name: [] for name in PLACEMENTS}
    for i, cut in enumerate(int(c) for c in peaks):
        if only is not None and not only[i]:
            for name in PLACEMENTS:
                stages[name].append(cut)
            continue
        # Never look past half-way to a neighbouring cut: that stretch is theirs.
        lo = max(0, cut - context, (int(peaks[i - 1]) + cut) // 2 if i else 0)
        hi = min(len(x), cut + context)
        if i + 1 < len(peaks):
            hi = min(hi, (cut + int(peaks[i + 1])) // 2)
        split = best_split(x, cut, lo, hi, step=step, radius=radius, gamma=gamma)
        turn = nearest(turns, split, radius)
        pause = settle_frame(speed, turn, radius, context)
        stages["split"].append(split)
        stages["turn"].append(turn)
        stages["pause"].append(pause)
        limit = (cut + int(peaks[i + 1])) // 2 if i + 1 < len(peaks) else len(x) - 1
        stages["onset"].append(onset_frame(fine, pause, min(limit, pause + onset_radius),
                                           context))
    return {k: np.asarray(v, dtype=np.int64) for k, v in stages.items()}, speed


@dataclass(frozen=True)
class Placement:
    """Where the detector puts each cut.

    stages : ``PLACEMENTS`` name -> (n_cuts,) int frames of ``Analysis.x``, each step
        starting from the previous one's result.
    stage : the step whose estimate is the cut (``shipped_stage``).
    speed : (n,) the 1 Hz pose speed (pauses; shown beside the cuts).
    turns : (n_turns,) int frames of ``Analysis.x`` where the 3 Hz pose speed has a local
        minimum (the turning points the second step moves to).
    """

    stages: dict[str, np.ndarray]
    stage: str
    speed: np.ndarray
    turns: np.ndarray

    @property
    def cuts(self) -> np.ndarray:
        """(n_cuts,) int frames of ``Analysis.x``: the estimate of ``stage``."""
        return self.stages[self.stage]


def place(analysis, found, p: dict) -> Placement:
    """Each placement step's estimate of every cut of ``found`` (a ``Peaks``)."""
    speed, fine = analysis.speeds
    stages = place_samples(analysis, found.samples, p)
    return Placement(stages, shipped_stage(p), speed, speed_minima(fine))


def place_samples(analysis, samples: np.ndarray, p: dict,
                  only: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Each placement step's estimate (frames of ``analysis.x``) of a cut at each of the
    novelty ``samples`` (increasing), each bounded half-way to its neighbours as
    ``place`` bounds the detector's cuts; with ``only`` ((n,) bool), the others are
    neighbours only and keep their own frame (``place_stages``)."""
    return place_stages(analysis.x, analysis.peak_frames(samples), analysis.fps,
                        analysis.gamma, p, analysis.speeds, only=only)[0]
