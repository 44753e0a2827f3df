"""A take: one capture's skeleton and its per-frame channel values."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from motionlib.skeleton import Skeleton


@dataclass(eq=False)
class Take:
    """One motion-capture take.

    Attributes
    ----------
    name : str
        Usually the file stem (``"13_29"``).
    format : {"bvh", "amc", "fbx"}
        The format it was read from.
    fps : float
        Frames per second (``1 / frame_time``, snapped to a whole number when within 0.1 %).
    frame_time : float
        Seconds per frame as stored in the file (kept for writing the file back).
    channels : ndarray of float64, shape (n_frames, n_channels)
        Channel values; time on axis 0, columns in the skeleton's joint order. Positions are in
        the file's length unit, rotations in degrees.
    skeleton : Skeleton
    rest_pose_frame : int or None
        Index of a rest (T-) pose frame detected at the start of the take, else None.
    path : str or None
        The file it was read from, if any (used in error messages).
    animation : str or None
        Which animation of a file holding several (FBX actions), else None.
    """

    name: str
    format: str
    fps: float
    frame_time: float
    channels: np.ndarray
    skeleton: Skeleton
    rest_pose_frame: int | None = None
    path: str | None = None
    animation: str | None = None

    @property
    def n_frames(self) -> int:
        return int(self.channels.shape[0])

    @property
    def duration(self) -> float:
        """Length in seconds, ``n_frames / fps``."""
        return self.n_frames / self.fps

    def slice(self, start: int | None = None, stop: int | None = None) -> Take:
        """Frames ``start`` (0-based) up to ``stop`` (exclusive), same skeleton and frame time.

        Raises ``ValueError`` naming the bounds when they are outside the take or empty.
        """
        start, stop = frame_range(self.n_frames, start, stop)
        rest = self.rest_pose_frame
        rest = rest - start if rest is not None and start <= rest < stop else None
        return replace(self, channels=self.channels[start:stop], rest_pose_frame=rest)


def frame_range(n_frames: int, start: int | None, stop: int | None) -> tuple[int, int]:
    """Validate a 0-based, stop-exclusive frame range against a take of ``n_frames``."""
    start = 0 if start is None else int(start)
    stop = n_frames if stop is None else int(stop)
    if not 0 <= start < stop <= n_frames:
        raise ValueError(f"frame range [{start}, {stop}) is empty or outside the take's "
                         f"{n_frames} frames")
    return start, stop
