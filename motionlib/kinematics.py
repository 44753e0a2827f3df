"""Euler angles to rotation matrices and forward kinematics over all frames at once.

Conventions (BVH): column vectors, a joint's rotation channels compose in the order they are
listed (``Zrotation Yrotation Xrotation`` gives ``R = Rz @ Ry @ Rx``), and a child sits at
``parent position + parent global rotation @ offset``. Angles are degrees.
"""

from __future__ import annotations

import numpy as np

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


def _joint_columns(skeleton):
    """Per joint: (translation columns by axis, rotation columns in composition order)."""
    starts = skeleton.channel_starts
    layout = []
    for j, names in enumerate(skeleton.channels):
        col = {name: starts[j] + k for k, name in enumerate(names)}
        trans = [col.get(f"{a}position") for a in "XYZ"]
        rots = [(_AXIS[a], col[f"{a}rotation"]) for a in skeleton.rotation_orders[j]
                if f"{a}rotation" in col]
        layout.append((trans, rots))
    return layout


def _local_translation(offset, trans_cols, channels):
    """Joint translation in its parent's frame: (3, 1), or (3, n_frames) with position channels."""
    if all(c is None for c in trans_cols):
        return offset[:, None]
    # Position channels replace the offset component they name (BVH root convention).
    return np.stack([channels[:, c] if c is not None else np.full(len(channels), offset[a])
                     for a, c in enumerate(trans_cols)])


def forward_kinematics(take, channels: np.ndarray | None = None) -> np.ndarray:
    """World positions of every joint in every frame.

    Parameters
    ----------
    take : Take
        Its skeleton gives offsets, channel layout, rotation orders and (ASF) axes.
    channels : ndarray, shape (n_frames, n_channels), optional
        Channel values to use instead of ``take.channels`` (rotations in degrees).

    Returns
    -------
    positions : ndarray of float64, shape (n_frames, n_joints, 3)
        In the file's length unit, Y up. Joint j's position is the point it rotates about (for
        an ASF bone, the start of the bone).

    Notes
    -----
    Vectorised over frames; the only Python loop is over joints. Internally a joint's position
    is laid out (3, n_frames) and its global rotation (3, 3, n_frames) so that every operation
    runs over contiguous frames; both are dropped once the joint's last child has used them,
    which bounds memory by the depth of the tree.
    """
    skeleton = take.skeleton
    channels = take.channels if channels is None else np.asarray(channels, dtype=np.float64)
    n, J = channels.shape[0], skeleton.n_joints
    out = np.empty((n, J, 3))
    last_child = {int(p): j for j, p in enumerate(skeleton.parents) if p >= 0}
    pos: dict[int, np.ndarray] = {}
    glob: dict[int, np.ndarray] = {}
    for j, (trans_cols, rots) in enumerate(_joint_columns(skeleton)):
        p = int(skeleton.parents[j])
        t = _local_translation(skeleton.offsets[j], trans_cols, channels)
        if p < 0:
            here = np.broadcast_to(t, (3, n)).copy()
            G = np.broadcast_to(np.eye(3)[:, :, None], (3, 3, n)).copy()
        else:
            Gp = glob[p]
            here = pos[p] + _apply(Gp, t) if t.any() else pos[p]
            G = Gp if j in last_child else None
        out[:, j] = here.T
        if G is not None:  # leaves need neither a rotation nor a kept position
            glob[j] = _rotate(G, rots, channels, skeleton.axes, j)
            pos[j] = here
        if p >= 0 and last_child[p] == j:
            del glob[p], pos[p]
    return out


def _apply(G: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``G @ t`` for G laid out (3, 3, n) and t (3, 1) or (3, n); result (3, n)."""
    if t.shape[1] == 1:
        return np.einsum("ijn,j->in", G, t[:, 0])
    return np.einsum("ijn,jn->in", G, t)


def _turn(G: np.ndarray, axis: int, c: np.ndarray, s: np.ndarray) -> None:
    """In place ``G <- G @ R_axis(angle)`` for matrices laid out (3, 3, n); c, s of the angle."""
    i, k = _MIXED[axis]
    gi = G[:, i].copy()
    gk = G[:, k]
    G[:, i] *= c
    G[:, i] += gk * s
    gk *= c
    gk -= gi * s


def _times_constant(G: np.ndarray, C: np.ndarray) -> np.ndarray:
    """``G @ C`` for G laid out (3, 3, n) and one matrix C (3, 3)."""
    return np.einsum("ikn,kj->ijn", G, C)


def _rotate(Gp, rots, channels, axes, j):
    """``Gp @ C @ R(channels) @ C.T`` with C the ASF axis frame (identity for BVH).

    Returns ``Gp`` itself (not a copy) when the joint never rotates; never modifies it.
    """
    degrees = np.ascontiguousarray(channels[:, [col for _, col in rots]].T)
    moving = degrees.any(axis=1)  # converters fill unused channels with zeros: skip them
    if not moving.any():
        return Gp
    G = _times_constant(Gp, axes[j]) if axes is not None else Gp.copy()
    sin, cos = sincos_degrees(degrees[moving])
    turns = [axis for (axis, _), m in zip(rots, moving, strict=True) if m]
    for k, axis in enumerate(turns):
        _turn(G, axis, cos[k], sin[k])
    if axes is not None:
        G = _times_constant(G, axes[j].T)
    return G


_TABLE_STEP = 0.1  # degrees
_TABLE_LIMIT = 720  # degrees either side of zero
_table: tuple[np.ndarray, np.ndarray] | None = None


def sincos_degrees(degrees: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sin, cos)`` of angles in degrees, to a few ulp, about 3x faster than np.sin + np.cos.

    float64 ``np.sin``/``np.cos`` run at ~9 ns a value here and were most of forward
    kinematics. Instead: the nearest multiple of 0.1 degree from a table, then the angle-sum
    formulas with short series for the remainder (below 0.05 degree the omitted terms are
    under 1e-17). Angles beyond ±720 degrees go to numpy.

    Parameters
    ----------
    degrees : ndarray

    Returns
    -------
    sin, cos : ndarray, same shape
    """
    global _table
    if degrees.size == 0 or np.abs(degrees).max() > _TABLE_LIMIT:
        radians = np.deg2rad(degrees)
        return np.sin(radians), np.cos(radians)
    half = round(_TABLE_LIMIT / _TABLE_STEP)
    if _table is None:
        # k * step, computed exactly as for `fine` below, so table and remainder agree.
        grid = np.deg2rad(np.arange(-half, half + 1) * _TABLE_STEP)
        _table = (np.sin(grid), np.cos(grid))
    steps = np.rint(degrees / _TABLE_STEP)
    fine = degrees - steps * _TABLE_STEP
    fine *= np.pi / 180
    index = steps.astype(np.intp)
    index += half
    sin_coarse, cos_coarse = _table[0][index], _table[1][index]
    fine2 = fine * fine
    sin_fine = fine * (1 - fine2 / 6)
    cos_fine = 1 - fine2 / 2 * (1 - fine2 / 12)
    return (sin_coarse * cos_fine + cos_coarse * sin_fine,
            cos_coarse * cos_fine - sin_coarse * sin_fine)


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
        A take: the vertical (Y) extent of its rest pose, End Sites included. Positions: the
        median over frames of each frame's vertical extent.

    Returns
    -------
    float
        In the file's length unit.
    """
    if hasattr(take_or_positions, "skeleton"):
        y = rest_positions(take_or_positions)[:, 1]
        return float(y.max() - y.min())
    positions = np.asarray(take_or_positions, dtype=np.float64)
    if positions.ndim != 3 or positions.shape[-1] != 3 or positions.shape[0] == 0:
        raise ValueError(f"positions must have shape (n_frames, n_joints, 3), got {positions.shape}")
    y = positions[..., 1]
    return float(np.median(y.max(axis=1) - y.min(axis=1)))
