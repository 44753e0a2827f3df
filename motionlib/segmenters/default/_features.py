"""Stage 1 of the default detector: per-frame pose features.

A frame becomes a vector that ignores where the performer stands and which way they
face (joint positions in the body frame, plus the root height, which separates squatting
and jumping from standing); a take known only by a few angle channels uses those angles.
"""

from __future__ import annotations

import numpy as np

from motionlib import features
from motionlib.kinematics import body_frame_rows
from motionlib.segmenters.base import first_frame, take_positions
from motionlib.skeleton import canonical_indices

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
    return _with_velocities(x, fps=fps, velocity_s=velocity_s)


def _with_velocities(x: np.ndarray, *, fps: float, velocity_s: float) -> np.ndarray:
    if velocity_s > 0:
        smooth = features.lowpass(x, fps=fps, cutoff_hz=min(3.0, 0.45 * fps))
        x = np.concatenate([x, np.gradient(smooth, axis=0) * fps * velocity_s], axis=1)
    return x


def take_features(take, *, velocity_s: float = 0.0) -> tuple[np.ndarray, int]:
    """The detector's per-frame feature vectors of a take.

    A take with a skeleton gives ``pose_features``; a take known only by a few angle
    channels (``benchdata.ChannelTake``, no ``skeleton``) gives those angles in radians:
    the kernel's width follows the data (median heuristic), so any unit works.

    Returns
    -------
    x : (n_used, n_features); first : take frame of ``x[0]`` (after a rest pose).
    """
    if getattr(take, "skeleton", None) is None:
        return np.radians(np.asarray(take.channels, dtype=float)), 0
    if getattr(take, "positions", None) is not None:  # computed already: used as they are
        positions, joints, first = take_positions(take)
        return pose_features(positions, joints, fps=float(take.fps), velocity_s=velocity_s), first
    # Else the same features straight from the channels, without every joint's positions.
    joints, first = canonical_indices(take), first_frame(take)
    x = body_frame_rows(take, [joints[j] for j in POSE_JOINTS], root=joints["root"],
                        left_hip=joints["left_hip"], right_hip=joints["right_hip"], first=first)
    x[:, -1] -= np.median(x[:, -1])
    return _with_velocities(x, fps=float(take.fps), velocity_s=velocity_s), first


def block_mean(x: np.ndarray, step: int) -> np.ndarray:
    """Average consecutive blocks of ``step`` frames: (n, d) -> (n // step, d)."""
    n = len(x) // step
    return x[: n * step].reshape(n, step, -1).mean(axis=1)


def median_sq_distance(x: np.ndarray, max_points: int = 1000) -> float:
    """Median squared distance between rows (on an even subsample for long inputs)."""
    sub = x[:: max(1, len(x) // max_points)]
    sq = (sub * sub).sum(axis=1)
    d2 = sq[:, None] + sq[None, :] - 2 * sub @ sub.T
    # The pairs above the diagonal, row by row: the order np.triu_indices gives, without
    # its two index arrays of n² / 2 entries each.
    return float(np.median(np.concatenate([row[i + 1:] for i, row in enumerate(d2)])))
