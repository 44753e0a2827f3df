"""Euler angles to rotation matrices and forward kinematics over all frames at once.

Conventions (BVH): column vectors, a joint's rotation channels compose in the order they are
listed (``Zrotation Yrotation Xrotation`` gives ``R = Rz @ Ry @ Rx``), and a child sits at
``parent position + parent global rotation @ offset``. Angles are degrees.
"""

from __future__ import annotations

import numpy as np

from motionlib import _kinematics, threads
from motionlib.errors import InputError

_AXIS = {"X": 0, "Y": 1, "Z": 2}
# Columns mixed by a right-multiplied rotation about each axis: G @ R_axis(θ).
_MIXED = {0: (1, 2), 1: (2, 0), 2: (0, 1)}


def rotate_columns(G: np.ndarray, axis: int, angle_deg: np.ndarray) -> None:
    """In place ``G <- G @ R_axis(angle)`` for a stack of matrices.

    Mixing two columns costs a handful of vector operations, far less than a batched 3x3
    matmul, which is why forward kinematics composes rotations this way.

    Parameters
    ----------
    G : ndarray, shape (n, 3, 3)
    axis : {0, 1, 2}
        X, Y or Z.
    angle_deg : ndarray, shape (n,)
    """
    theta = np.deg2rad(angle_deg)[:, None]
    c, s = np.cos(theta), np.sin(theta)
    i, k = _MIXED[axis]
    gi = G[:, :, i].copy()
    gk = G[:, :, k]
    G[:, :, i] = gi * c + gk * s
    G[:, :, k] = gk * c - gi * s


def euler_to_matrix(angles_deg: np.ndarray, order: str) -> np.ndarray:
    """Rotation matrices from Euler angles.

    Parameters
    ----------
    angles_deg : ndarray, shape (n, len(order))
        Angles in degrees, column k about axis ``order[k]``.
    order : str
        Composition order, e.g. ``"ZYX"`` for ``R = Rz @ Ry @ Rx``.

    Returns
    -------
    ndarray, shape (n, 3, 3)
    """
    angles_deg = np.asarray(angles_deg, dtype=np.float64).reshape(-1, len(order))
    R = np.broadcast_to(np.eye(3), (len(angles_deg), 3, 3)).copy()
    for k, axis in enumerate(order):
        rotate_columns(R, _AXIS[axis], angles_deg[:, k])
    return R


def matrix_to_euler_zyx(R: np.ndarray) -> np.ndarray:
    """Euler angles ``(z, y, x)`` in degrees with ``R = Rz @ Ry @ Rx``.

    Parameters
    ----------
    R : ndarray, shape (n, 3, 3)

    Returns
    -------
    ndarray, shape (n, 3)
        Columns z, y, x; y in [-90, 90]. At y = ±90 (gimbal lock) x is set to 0 and z carries
        the whole remaining rotation, so the matrix is still reproduced exactly.
    """
    cy = np.hypot(R[:, 0, 0], R[:, 1, 0])
    y = np.arctan2(-R[:, 2, 0], cy)  # better conditioned near ±90 than arcsin
    locked = cy < 1e-12
    z = np.where(locked, np.arctan2(-R[:, 0, 1], R[:, 1, 1]), np.arctan2(R[:, 1, 0], R[:, 0, 0]))
    x = np.where(locked, 0.0, np.arctan2(R[:, 2, 1], R[:, 2, 2]))
    return np.rad2deg(np.stack([z, y, x], axis=1))


_MAX_ROTATIONS = 3  # rotation channels per joint, as in _kinematics.c


def _layout(skeleton):
    """The skeleton as the flat arrays ``_kinematics.positions`` walks (see its docstring)."""
    J = skeleton.n_joints
    position = np.full((J, 3), -1, np.intp)
    rotation = np.full((J, _MAX_ROTATIONS, 2), -1, np.intp)
    for j, (names, first) in enumerate(zip(skeleton.channels, skeleton.channel_starts,
                                           strict=True)):
        col = {name: first + k for k, name in enumerate(names)}
        for a, axis in enumerate("XYZ"):
            position[j, a] = col.get(f"{axis}position", -1)
        rots = [(_AXIS[a], col[f"{a}rotation"]) for a in skeleton.rotation_orders[j]
                if f"{a}rotation" in col]
        if len(rots) > _MAX_ROTATIONS:
            raise InputError(f"joint {skeleton.names[j]!r} has {len(rots)} rotation channels; "
                             f"at most {_MAX_ROTATIONS} are supported")
        if rots:
            rotation[j, :len(rots)] = rots
    axes = None if skeleton.axes is None else np.ascontiguousarray(skeleton.axes, np.float64)
    return (np.asarray(skeleton.parents, np.intp),
            np.ascontiguousarray(skeleton.offsets, np.float64), position, rotation, axes)


def _channels(skeleton, channels) -> np.ndarray:
    """``channels`` as the compiled walk reads them: contiguous float64, one row per frame
    with the skeleton's channels (an InputError naming the shape otherwise)."""
    channels = np.ascontiguousarray(channels, dtype=np.float64)
    if channels.ndim != 2 or channels.shape[1] != skeleton.n_channels:
        raise InputError(f"channels must have shape (n_frames, {skeleton.n_channels}), got "
                         f"{channels.shape}")
    return channels


def forward_kinematics(take, channels: np.ndarray | None = None) -> np.ndarray:
    """World positions of every joint in every frame.

    Parameters
    ----------
    take : Take
        Its skeleton gives offsets, channel layout, rotation orders and (ASF) axes. A point
        take (``motionlib.points``) has its points already: a copy of them, NaN at gaps.
    channels : ndarray, shape (n_frames, n_channels), optional
        Channel values to use instead of ``take.channels`` (rotations in degrees).

    Returns
    -------
    positions : ndarray of float64, shape (n_frames, n_joints, 3)
        In the file's length unit, Y up. Joint j's position is the point it rotates about (for
        an ASF bone, the start of the bone).

    Notes
    -----
    All frames in one call to compiled code (``motionlib/_kinematics.c``), which walks frame
    by frame with each joint's global rotation in a small scratch array. The numpy formulation
    it replaced (a Python loop over joints, each step a pass over all frames) took 10-30 ms on
    the 4,593 frames of CMU 13_29, mostly moving arrays through memory; this takes ~6 ms.
    Angles use a table at whole degrees plus a short series, a few ulp from the exact value;
    zero angles are skipped exactly, and leaves (whose rotation moves no joint) not rotated.
    """
    skeleton = take.skeleton
    if skeleton.point_set:  # a point take (motionlib.points): its points, gaps NaN
        return np.array(take.positions, dtype=np.float64)
    channels = _channels(skeleton, take.channels if channels is None else channels)
    out = np.empty((channels.shape[0], skeleton.n_joints, 3))
    layout = _layout(skeleton)
    # Frames are independent: a long take's halves are walked at once (``motionlib.threads``).
    parts = threads.threads() if channels.shape[0] >= PARALLEL_FRAMES else 1
    threads.run_all([
        lambda a=a, b=b: _kinematics.positions(channels[a:b], b - a, skeleton.n_channels,
                                               *layout, out[a:b])
        for a, b in threads.bounds(channels.shape[0], parts)])
    return out


# Frames from which forward kinematics is worth splitting over threads (~50 ms of work).
PARALLEL_FRAMES = 50_000


def body_frame_rows(take, chosen: list[int], *, root: int, left_hip: int, right_hip: int,
                    first: int = 0) -> np.ndarray:
    """``features.body_frame_positions`` of the ``chosen`` joints and the root's height,
    straight from the channels of frames ``first ..``.

    The same values as computing ``forward_kinematics`` and then those features, without
    writing every joint of every frame to memory first: each frame's positions stay in a
    small scratch array (``_kinematics.body_frame``), which makes it several times faster
    on a take of minutes.

    Returns
    -------
    (n_frames - first, 3 len(chosen) + 1): per frame, each chosen joint's body-frame x, y,
    z, then the root's height (Y).
    """
    skeleton = take.skeleton
    channels = _channels(skeleton, take.channels[first:])
    out = np.empty((channels.shape[0], 3 * len(chosen) + 1))
    _kinematics.body_frame(channels, channels.shape[0], skeleton.n_channels, *_layout(skeleton),
                           np.asarray(chosen, dtype=np.intp), root, left_hip, right_hip, out)
    return out


def rest_positions(take) -> np.ndarray:
    """Joint and End Site positions with every channel at zero, shape (n_joints + n_ends, 3)."""
    skeleton = take.skeleton
    zero = np.zeros((1, skeleton.n_channels))
    joints = forward_kinematics(take, zero)[0]
    # At rest every global rotation is the identity (ASF: C @ I @ C.T), so ends are plain sums.
    ends = [joints[j] + off for j, off in skeleton.end_sites.items()]
    return np.vstack([joints, *ends]) if ends else joints


def skeleton_height(take_or_positions) -> float:
    """Head-to-toe height, a scale for tolerances.

    Parameters
    ----------
    take_or_positions : Take or ndarray of shape (n_frames, n_joints, 3)
        A take: the vertical (Y) extent of its rest pose, End Sites included (a point take:
        the median over frames of the extent of the points seen). Positions: the median over
        frames of each frame's vertical extent.

    Returns
    -------
    float
        In the file's length unit.
    """
    if hasattr(take_or_positions, "skeleton"):
        if take_or_positions.skeleton.point_set:
            return _seen_height(take_or_positions.positions)
        y = rest_positions(take_or_positions)[:, 1]
        return float(y.max() - y.min())
    positions = np.asarray(take_or_positions, dtype=np.float64)
    if positions.ndim != 3 or positions.shape[-1] != 3 or positions.shape[0] == 0:
        raise InputError(f"positions must have shape (n_frames, n_joints, 3), got {positions.shape}")
    y = positions[..., 1]
    return float(np.median(y.max(axis=1) - y.min(axis=1)))


def _seen_height(positions: np.ndarray) -> float:
    """Median vertical extent of the points seen in each frame (frames with one seen at
    least); 0 when no frame has any."""
    y = np.asarray(positions, dtype=np.float64)[..., 1]
    seen = ~np.isnan(y).all(axis=1)
    if not seen.any():
        return 0.0
    y = y[seen]
    return float(np.median(np.nanmax(y, axis=1) - np.nanmin(y, axis=1)))


def local_transforms(take) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's rotation and translation relative to its parent, every frame, of a
    ``motionlib.take.Take`` (the exporters' common step: BVH-free writers such as glTF
    key these, where FBX and BVH write the channels).

    Returns
    -------
    rotations : ndarray, shape (n_frames, n_joints, 3, 3)
        From the rotation channels in the joint's order (``C @ R @ C.T`` with ASF axes).
    translations : ndarray, shape (n_frames, n_joints, 3)
        The offset, with position channels replacing its axes where the joint has them.
    """
    sk = take.skeleton
    n = take.n_frames
    rotations = np.broadcast_to(np.eye(3), (n, sk.n_joints, 3, 3)).copy()
    translations = np.broadcast_to(sk.offsets, (n, sk.n_joints, 3)).copy()
    for j, (names, first) in enumerate(zip(sk.channels, sk.channel_starts, strict=True)):
        column = {name: first + k for k, name in enumerate(names)}
        for a, axis in enumerate("XYZ"):
            if f"{axis}position" in column:
                translations[:, j, a] = take.channels[:, column[f"{axis}position"]]
        order = "".join(a for a in sk.rotation_orders[j] if f"{a}rotation" in column)
        if order:
            angles = take.channels[:, [column[f"{a}rotation"] for a in order]]
            R = euler_to_matrix(angles, order)
            if sk.axes is not None:
                R = sk.axes[j] @ R @ sk.axes[j].T
            rotations[:, j] = R
    return rotations, translations
