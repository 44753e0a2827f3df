"""Per-frame motion features and 1-D signal helpers used by the segmenters.

Positions are world joint positions ``(n_frames, n_joints, 3)`` (Y up) as returned by
``motionlib.forward_kinematics``; ``joints`` maps canonical names ("root", "chest",
"left_elbow", ...) to joint indices as returned by ``motionlib.canonical_indices``.
Time is axis 0 everywhere.
"""

from __future__ import annotations

import numpy as np
from scipy import signal as sps

from motionlib import threads

# The 8 limb bones of the 2011 bone-angle paper: (upper joint, lower joint).
LIMB_BONES = (
    ("left_shoulder", "left_elbow"),
    ("left_elbow", "left_wrist"),
    ("right_shoulder", "right_elbow"),
    ("right_elbow", "right_wrist"),
    ("left_hip", "left_knee"),
    ("left_knee", "left_ankle"),
    ("right_hip", "right_knee"),
    ("right_knee", "right_ankle"),
)

# Nine joint-to-joint distances for the joint-distance PCA method. The patent's own
# table is lost; these are chosen so each has a plain meaning an animator would use.
JOINT_DISTANCES = (
    ("left_wrist", "right_wrist"),  # hands apart (claps, arm circles, jumping jacks)
    ("left_ankle", "right_ankle"),  # feet apart (stride, stance width)
    ("left_wrist", "head"),  # left hand raised to the head
    ("right_wrist", "head"),  # right hand raised to the head
    ("left_wrist", "left_hip"),  # left hand reaching down / out
    ("right_wrist", "right_hip"),  # right hand reaching down / out
    ("left_ankle", "left_hip"),  # left leg flexion (squat, knee raise)
    ("right_ankle", "right_hip"),  # right leg flexion
    ("left_knee", "right_knee"),  # knees apart
)


def _unit(v: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(norm, 1e-12)


def bone_angles(positions: np.ndarray, joints: dict[str, int]) -> np.ndarray:
    """Angles between the 8 limb bones and the centre bone (root -> chest).

    Parameters
    ----------
    positions : (n_frames, n_joints, 3) world joint positions.
    joints : canonical joint name -> index.

    Returns
    -------
    (n_frames, 8) angles in radians, in the order of ``LIMB_BONES``.
    """
    centre = _unit(positions[:, joints["chest"]] - positions[:, joints["root"]])
    upper = positions[:, [joints[a] for a, _ in LIMB_BONES]]
    lower = positions[:, [joints[b] for _, b in LIMB_BONES]]
    bones = _unit(lower - upper)
    cosine = np.einsum("fbk,fk->fb", bones, centre)
    return np.arccos(np.clip(cosine, -1.0, 1.0))


def joint_distances(positions: np.ndarray, joints: dict[str, int]) -> np.ndarray:
    """The 9 joint-to-joint distances of ``JOINT_DISTANCES``.

    Returns
    -------
    (n_frames, 9) distances in the capture's length unit.
    """
    a = positions[:, [joints[p] for p, _ in JOINT_DISTANCES]]
    b = positions[:, [joints[q] for _, q in JOINT_DISTANCES]]
    return np.linalg.norm(a - b, axis=-1)


def body_frame_positions(
    positions: np.ndarray, joints: dict[str, int], which: list[int] | None = None
) -> np.ndarray:
    """Joint positions relative to the root, with the body's heading removed.

    The heading is the horizontal direction of the hip axis (left hip -> right hip)
    turned a quarter turn; each frame is rotated about Y so that it faces +Z. The
    result does not change when the performer walks somewhere else or turns round.

    Parameters
    ----------
    which : joint indices to return (all joints when None).

    Returns
    -------
    (n_frames, n_joints or len(which), 3) positions, same unit as the input.
    """
    n_chosen = positions.shape[1] if which is None else len(which)
    out = np.empty((positions.shape[0], n_chosen, 3))
    # Frames are independent: a long take's halves are turned at once (motionlib.threads).
    parts = threads.threads() if len(positions) >= PARALLEL_FRAMES else 1
    threads.run_all([lambda a=a, b=b: _body_frame(positions[a:b], joints, which, out[a:b])
                     for a, b in threads.bounds(len(positions), parts)])
    return out


# Frames from which the body frame is worth splitting over threads.
PARALLEL_FRAMES = 50_000


def _body_frame(positions, joints, which, out):
    """``body_frame_positions`` of ``positions`` written into ``out``."""
    # np.take copies the chosen joints several times faster than fancy indexing does.
    chosen = positions if which is None else np.take(positions, which, axis=1)
    root = positions[:, joints["root"]]
    hips = positions[:, joints["right_hip"]] - positions[:, joints["left_hip"]]
    c, s = heading_cos_sin(hips[:, 0], hips[:, 2])
    c, s = c[:, None], s[:, None]
    x = chosen[..., 0] - root[:, 0:1]
    z = chosen[..., 2] - root[:, 2:3]
    np.subtract(chosen[..., 1], root[:, 1:2], out=out[..., 1])
    # Rotate about Y by +angle so the hip axis lies on +X for every frame.
    out[..., 0] = c * x + s * z
    out[..., 2] = -s * x + c * z


def heading_cos_sin(dx: np.ndarray, dz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cosine and sine of the angle of the ground-plane vectors ``(dx, dz)`` from +X: the
    vector over its length; (1, 0), no turn, for a zero vector.

    Division and square root round the same way on every CPU, unlike numpy's
    trigonometry (its AVX-512 builds use their own, a few ulp from the C library's), so
    the compiled ``kinematics.body_frame_rows`` gets the same values to the last bit.
    """
    length = np.sqrt(dx * dx + dz * dz)
    flat = length == 0
    safe = np.where(flat, 1.0, length)
    return np.where(flat, 1.0, dx / safe), np.where(flat, 0.0, dz / safe)


def lowpass(y: np.ndarray, *, fps: float, cutoff_hz: float, order: int = 2) -> np.ndarray:
    """Zero-phase Butterworth low-pass filter along axis 0.

    Parameters
    ----------
    y : (n_frames, ...) signal sampled at ``fps`` frames per second.
    cutoff_hz : cutoff frequency in Hz; at or above Nyquist the input is returned.
    """
    y = np.asarray(y, dtype=float)
    if cutoff_hz >= fps / 2:
        return y.copy()
    sos = sps.butter(order, cutoff_hz, fs=fps, output="sos")
    padlen = max(min(3 * (2 * len(sos) + 1), y.shape[0] - 1), 0)
    columns = y.reshape(len(y), -1)
    if len(y) < PARALLEL_FRAMES or columns.shape[1] < 2 or threads.threads() < 2:
        return sps.sosfiltfilt(sos, y, axis=0, padlen=padlen)
    # Columns are filtered independently: a long take's are split over threads.
    parts = threads.run_all([
        lambda a=a, b=b: sps.sosfiltfilt(sos, columns[:, a:b], axis=0, padlen=padlen)
        for a, b in threads.bounds(columns.shape[1], threads.threads())])
    return np.concatenate(parts, axis=1).reshape(y.shape)


def local_extrema(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interior local maxima and minima of a 1-D signal, in time order.

    Flat runs count once (at their last frame). Consecutive extrema alternate
    between maximum and minimum.

    Returns
    -------
    indices : (n_extrema,) int frame indices.
    is_max : (n_extrema,) bool, True for a maximum.
    """
    step = np.sign(np.diff(np.asarray(y, dtype=float)))
    nonzero = np.flatnonzero(step)
    if len(nonzero) < 2:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool)
    signs = step[nonzero]
    turn = np.flatnonzero(signs[1:] != signs[:-1])
    # The extremum sits where the last rising (falling) step ends.
    indices = nonzero[turn] + 1
    return indices.astype(np.int64), signs[turn] > 0


def swings(y: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signal swing from each extremum to its neighbouring extrema.

    ``indices`` are alternating extrema (``local_extrema``); the neighbour on each side
    is therefore the nearest extremum of the opposite kind. At the ends the first/last
    sample of ``y`` stands in for the missing neighbour.

    Returns
    -------
    left, right : (n_extrema,) absolute signal differences.
    """
    y = np.asarray(y, dtype=float)
    values = y[indices]
    before = np.concatenate([[y[0]], values[:-1]])
    after = np.concatenate([values[1:], [y[-1]]])
    return np.abs(values - before), np.abs(values - after)


def swing_test(
    y: np.ndarray, indices: np.ndarray, factor: float
) -> tuple[np.ndarray, np.ndarray]:
    """The amplitude test shared by both published methods.

    An extremum passes when ``min(left, right) <= factor * max(left, right)``: the
    signal settles on one side and moves a lot on the other, which is what a change of
    activity looks like, while an oscillation inside one activity swings evenly.

    Returns
    -------
    passed : (n_extrema,) bool.
    strength : (n_extrema,) float in [0, 1], ``1 - min/max`` (1 = fully one-sided).
    """
    left, right = swings(y, indices)
    big = np.maximum(left, right)
    small = np.minimum(left, right)
    ratio = np.divide(small, big, out=np.ones_like(big), where=big > 0)
    return (small <= factor * big) & (big > 0), 1.0 - ratio


def lowess(y: np.ndarray, span: int) -> np.ndarray:
    """Local linear regression smoothing of uniformly sampled data.

    Reproduces MATLAB ``smooth(y, span, 'lowess')``: each sample is replaced by the
    value at that sample of a straight line fitted by weighted least squares to its
    ``span`` nearest samples, with tricube weights ``(1 - (d / d_max)^3)^3`` where
    ``d_max`` is the distance to the farthest sample in the window. An even span is
    reduced by one (as MATLAB does), so interior windows are symmetric; near the ends
    the window is the first (last) ``span`` samples.

    For a symmetric window the fitted line's value at the centre is the weighted
    mean, so the interior is one convolution; only the ``span // 2`` samples at each
    end need their own small regressions.

    Parameters
    ----------
    y : (n,) samples.
    span : window length in samples (>= 3 after the odd adjustment is useful).

    Returns
    -------
    (n,) smoothed samples.
    """
    y = np.asarray(y, dtype=float)
    n = len(y)
    span = min(int(span), n)
    span -= 1 - span % 2
    if span < 3:
        return y.copy()
    h = span // 2
    offsets = np.arange(-h, h + 1)
    weights = (1 - (np.abs(offsets) / h) ** 3) ** 3
    out = np.empty(n)
    out[h : n - h] = np.convolve(y, weights[::-1] / weights.sum(), mode="valid")
    out[:h] = _edge_lowess(y[:span], np.arange(h))
    out[n - h :] = _edge_lowess(y[n - span :], np.arange(span - h, span))
    return out


def _edge_lowess(window: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """Weighted linear fits over one fixed window, evaluated at each target sample."""
    x = np.arange(len(window), dtype=float)
    d = np.abs(x[None, :] - targets[:, None])
    w = (1 - (d / d.max(axis=1, keepdims=True)) ** 3) ** 3
    sw = w.sum(axis=1)
    mx = (w @ x) / sw
    my = (w @ window) / sw
    dx = x[None, :] - mx[:, None]
    slope = (w * dx) @ window / np.maximum((w * dx * dx).sum(axis=1), 1e-300)
    return my + slope * (targets - mx)


def frame_speed(x: np.ndarray, *, fps: float) -> np.ndarray:
    """Frame-to-frame speed of a per-frame feature vector.

    Parameters
    ----------
    x : (n_frames, ...) features sampled at ``fps``.

    Returns
    -------
    (n_frames,) Euclidean norm of the central-difference derivative, units per second.
    """
    flat = np.asarray(x, dtype=float).reshape(len(x), -1)
    d = np.gradient(flat, axis=0)
    return np.sqrt(np.einsum("ij,ij->i", d, d)) * fps
