"""Joint-distance PCA cuts (patent CN102867300A).

Steps, as the patent describes them:

1. Nine joint-to-joint distances per frame (``features.JOINT_DISTANCES``; the patent's
   own table is lost, these are chosen to have a plain meaning).
2. PCA over the frames; the first principal component is the feature curve.
3. LOWESS smoothing as MATLAB ``smooth(y, span, 'lowess')`` (``features.lowess``).
4. Local extrema; an extremum is kept when ``min(swing) <= delta * max(swing)``.
5. The first and last frame are added; a cut closer than ``gamma`` frames to the
   previous *kept* cut is dropped.
6. Each cut p2 after the first is refined in the window ``[p2 - alpha, p2 + alpha]``:
   a window frame whose pose distance to the previous segment ``[p1, p2 - alpha]`` is
   below ``beta`` belongs to the previous segment; with N such frames the cut moves to
   ``p2 - alpha + N``.

Where the seed text is ambiguous this implementation takes the evident intent:

- The pseudo-code of the amplitude test compares extremum *indices*; the intent (and
  the 2011 paper's identical test) is to compare signal *values*, so swings are
  differences of the smoothed curve.
- "Pose distance to the previous segment" is the Euclidean distance over all channels
  (degrees and length units as stored) from the frame to the previous segment's mean
  pose, divided by the square root of the channel count (an RMS per channel) so that
  ``beta`` means the same for skeletons with different numbers of channels.
- p1 is the previous cut *after* its own refinement; the take's first and last frames
  are segment ends, not cuts, and are not moved. The window is clipped to the take and
  to the neighbouring cuts, so refined cuts stay in order.
- The PCA input is centred but not scaled (all nine distances share one unit).
- A point take has no channels: its pose is the coordinates of its body parts
  (``markersets.body_joints``), so ``beta`` is then in the take's length unit.

Frame parameters are in frames of the take, as in the patent (its figures are for
120 fps CMU captures). The defaults (span 31, delta 0.3, gamma 200, alpha 40, beta 8)
reproduce the patent's published run on CMU 13_30 (AMC): initial cuts (1-based)
1, 232, 800, 1385, 1969, 2336, 2465 against the published 1, 196, 800, 1384, 1966,
2425, 2465, and final cuts 1, 217, 818, 1345, 1929, 2369, 2465 against the published
1, 208, 803, 1364, 1949, 2384, 2465 (every one within 20 frames). They were chosen to
reproduce that run, not for the benchmark.
"""

from __future__ import annotations

import time

import numpy as np

from motionlib import features
from motionlib.segmenters.base import Param, Segmentation, Segmenter, full_length, take_positions


def first_component(x: np.ndarray) -> np.ndarray:
    """Scores of the centred rows of ``x`` (n, d) on their first principal axis, (n,)."""
    centred = x - x.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    axis = vt[0] * np.sign(vt[0][np.argmax(np.abs(vt[0]))])  # deterministic sign
    return centred @ axis


def thin_cuts(cuts: np.ndarray, gamma: int) -> np.ndarray:
    """Drop each cut closer than ``gamma`` frames to the previous kept cut."""
    kept: list[int] = []
    for c in cuts:
        if not kept or c - kept[-1] >= gamma:
            kept.append(int(c))
    return np.asarray(kept, dtype=np.int64)


def refine_cuts(
    channels: np.ndarray, cuts: np.ndarray, *, alpha: int, beta: float
) -> np.ndarray:
    """The patent's window refinement of interior cuts (see the module docstring).

    Parameters
    ----------
    channels : (n_frames, n_channels) pose of every frame.
    cuts : (n,) sorted frames; the first and last are the take's ends and stay put.
    alpha : half window (frames); beta : RMS channel distance threshold.
    """
    out = cuts.copy()
    scale = np.sqrt(channels.shape[1])
    for k in range(1, len(out) - 1):
        p1, p2 = out[k - 1], out[k]
        lo = max(p2 - alpha, p1 + 1)
        hi = min(p2 + alpha, out[k + 1] - 1, len(channels) - 1)
        if hi < lo:
            continue
        mean_pose = channels[p1:lo].mean(axis=0)
        dist = np.linalg.norm(channels[lo : hi + 1] - mean_pose, axis=1) / scale
        out[k] = lo + int(np.count_nonzero(dist < beta))
    return out


def pose_rows(take, positions: np.ndarray, first: int) -> np.ndarray:
    """The pose compared in the refinement: the channels of frames ``first ..``, or for a
    point take (no channels) the coordinates of its body parts, gaps closed."""
    if take.skeleton.point_set:
        return positions.reshape(len(positions), -1)
    return take.channels[first:]


class JointDistancePCA(Segmenter):
    name = "joint_distance_pca"
    title = "Joint-distance PCA (patent CN102867300A)"
    description = (
        "First principal component of nine joint distances, LOWESS-smoothed; one-sided "
        "extrema spaced at least gamma frames apart, refined by pose distance."
    )
    params = {
        # Cost grows with span and alpha (frames); bounded to keep long takes cheap.
        "span": Param("int", 31, 3, 2000, "LOWESS window (frames)."),
        "delta": Param(
            "float", 0.3, 0.0, 1.0,
            "Amplitude test: keep an extremum when min swing <= delta * max swing.",
        ),
        "gamma": Param("int", 200, 1, 1000000, "Minimum frames from the previous kept cut."),
        "alpha": Param("int", 40, 0, 2000, "Refinement half window (frames)."),
        "beta": Param(
            "float", 8.0, 0.0, 1e6,
            "Refinement: RMS channel distance below which a window frame belongs to the "
            "previous segment.",
        ),
    }

    def _segment(self, take, *, span, delta, gamma, alpha, beta) -> Segmentation:
        t0 = time.perf_counter()
        positions, joints, first = take_positions(take)
        t1 = time.perf_counter()
        curve = first_component(features.joint_distances(positions, joints))
        smooth = features.lowess(curve, span)
        idx, _ = features.local_extrema(smooth)
        passed, strength = features.swing_test(smooth, idx, delta)
        ends = np.array([0, len(curve) - 1])
        initial = thin_cuts(np.concatenate([[0], idx[passed], [len(curve) - 1]]), gamma)
        if initial[-1] != ends[-1]:
            initial = np.append(initial, ends[-1])
        t2 = time.perf_counter()
        final = refine_cuts(pose_rows(take, positions, first), initial, alpha=alpha, beta=beta)
        t3 = time.perf_counter()
        conf = dict(zip(idx.tolist(), strength.tolist(), strict=True))
        interior = slice(1, len(final) - 1)
        self.initial_cuts_ = initial + first
        return Segmentation(
            cuts=final[interior] + first,
            confidence=np.array([conf.get(int(c), 0.5) for c in initial[interior]]),
            signals={"pc1": full_length(curve, first), "pc1_smooth": full_length(smooth, first)},
            timings={"kinematics": t1 - t0, "detect": t2 - t1, "refine": t3 - t2},
        )
