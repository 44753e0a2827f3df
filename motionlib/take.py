"""A take: one capture's skeleton and its per-frame channel values."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from motionlib.errors import CaptureError, InputError, shorten
from motionlib.skeleton import Skeleton


@dataclass(eq=False)
class Take:
    """One motion-capture take.

    Attributes
    ----------
    name : str
        Usually the file stem (``"13_29"``).
    format : {"bvh", "amc", "fbx", "c3d", "tsv", "csv"}
        The format it was read from (the last three: a point take, ``motionlib.points``).
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
    positions : ndarray of float, shape (n_frames, n_joints, 3), or None
        World joint positions (``forward_kinematics(take)``) when a caller has computed
        them already; segmenters then use them instead of computing them again. Set them
        read-only (``flags.writeable = False``): segmenters do not change them.
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
    positions: np.ndarray | None = field(default=None, repr=False)

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
        positions = None if self.positions is None else self.positions[start:stop]
        return replace(self, channels=self.channels[start:stop], rest_pose_frame=rest,
                       positions=positions)


def frame_range(n_frames: int, start: int | None, stop: int | None) -> tuple[int, int]:
    """Validate a 0-based, stop-exclusive frame range against a take of ``n_frames``."""
    start = 0 if start is None else int(start)
    stop = n_frames if stop is None else int(stop)
    if not 0 <= start < stop <= n_frames:
        raise InputError(f"frame range [{start}, {stop}) is empty or outside the take's "
                         f"{n_frames} frames")
    return start, stop


@dataclass(frozen=True)
class Limits:
    """What a capture file may hold and expand to; readers check these before allocating.

    The defaults admit an hour of a CMU take at 120 fps (432,000 frames × 31 joints) and
    refuse files built to exhaust memory: ``Frames: 1000000000000``, 80,000 joints, or a
    small file of channel-less joints whose positions would be thousands of times its size.

    Attributes
    ----------
    max_joints : int
        Joints (BVH joints, ASF bones) in one skeleton.
    max_frames : int
        Frames in one take.
    max_values : int
        ``n_frames × n_channels``: the channel array, 8 bytes each.
    max_joint_frames : int
        ``n_frames × n_joints``: the world positions (3 float32, 12 bytes each).
    max_expansion : int
        The positions (12 bytes per joint per frame) may be at most this many times the
        size of the file, or :data:`EXPANSION_FLOOR_BYTES` when that is more.
    min_frames : int
        Frames a take needs: at least one by default, since a file declaring ``Frames: 0``
        holds a skeleton and no motion, which is not a take.
    min_frame_time, max_frame_time : float
        Seconds per frame (10 kHz to one frame every 10 s).
    max_length : float
        Largest absolute offset or position value, in the file's length unit.
    max_name_length : int
        Characters in a joint name.
    """

    max_joints: int = 1000
    max_frames: int = 2_000_000
    max_values: int = 60_000_000
    max_joint_frames: int = 20_000_000
    max_expansion: int = 16
    min_frames: int = 1
    min_frame_time: float = 1e-4
    max_frame_time: float = 10.0
    max_length: float = 1e6
    max_name_length: int = 200


DEFAULT_LIMITS = Limits()
EXPANSION_FLOOR_BYTES = 16 * 2**20
POSITION_BYTES = 12  # one joint in one frame: x, y, z as float32


def max_frames_for(n_joints: int, n_channels: int, file_bytes: int, limits: Limits) -> int:
    """The most frames a take of this shape, read from a file of ``file_bytes``, may have."""
    budget = max(limits.max_expansion * file_bytes, EXPANSION_FLOOR_BYTES) // POSITION_BYTES
    return min(limits.max_frames, limits.max_values // max(n_channels, 1),
               limits.max_joint_frames // max(n_joints, 1), budget // max(n_joints, 1))


def check_points(n_points: int, limits: Limits, path=None, line: int | None = None,
                 what: str = "points") -> None:
    """Refuse a point take (or an armature) of more than ``limits.max_joints`` points,
    before anything per point is built.

    Points count as joints: every later step (positions, links, descriptors) costs per
    point what it costs per joint, so a file of 33,334 markers is as hostile as a BVH of
    33,334 joints.

    Raises
    ------
    CaptureError
        Naming the count, the limit and (when given) the file and line.
    """
    if n_points > limits.max_joints:
        raise CaptureError(f"{n_points} {what} is more than the limit of {limits.max_joints} "
                           "joints", path=path, line=line)


def check_point_names(names: list[str], limits: Limits, path=None, line: int | None = None,
                      what: str = "point") -> None:
    """Refuse a point name longer than ``limits.max_name_length``, as a joint's is (a C3D
    label holds at most 255 characters, so a longer one could not be exported)."""
    long = next((name for name in names if len(name) > limits.max_name_length), None)
    if long is not None:
        raise CaptureError(f"{what} name {shorten(long)} is longer than the limit of "
                           f"{limits.max_name_length} characters", path=path, line=line)


def check_size(n_frames: int, n_joints: int, n_channels: int, file_bytes: int,
               limits: Limits, path=None, line: int | None = None) -> None:
    """Refuse a take whose arrays would exceed ``limits``, before they are allocated.

    Raises
    ------
    CaptureError
        Naming the count at fault, the limit and (when given) the file and line.
    """
    if limits.min_frames <= n_frames <= max_frames_for(n_joints, n_channels, file_bytes, limits):
        return
    budget = max(limits.max_expansion * file_bytes, EXPANSION_FLOOR_BYTES) // POSITION_BYTES
    joint_frames = n_frames * n_joints
    if n_frames < limits.min_frames:
        message = (f"the take has {n_frames} frame{'' if n_frames == 1 else 's'}; a capture "
                   f"needs at least {limits.min_frames}")
    elif n_frames > limits.max_frames:
        message = f"{n_frames} frames is more than the limit of {limits.max_frames}"
    elif n_frames * n_channels > limits.max_values:
        message = (f"{n_frames} frames × {n_channels} channels = {n_frames * n_channels} "
                   f"values is more than the limit of {limits.max_values}")
    elif joint_frames > limits.max_joint_frames:
        message = (f"{n_frames} frames × {n_joints} joints = {joint_frames} joint positions "
                   f"is more than the limit of {limits.max_joint_frames}")
    else:
        message = (f"{n_frames} frames × {n_joints} joints = {joint_frames} joint positions "
                   f"is too many for a {file_bytes}-byte file: their positions may take at "
                   f"most {limits.max_expansion} times its size ({budget} joint positions)")
    raise CaptureError(message, path=path, line=line)
