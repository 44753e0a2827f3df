"""How alike two clips move: segment descriptors and a distance between them.

Per frame, a clip is described by the 8 bone angles of the bone-angle method (radians)
and the positions of the hands, elbows, feet, knees and head in the body frame (root at
the origin, heading removed; see ``motionlib.features.body_frame_positions``) divided by
the performer's leg + trunk length. So nothing changes when the actor stands elsewhere,
faces another way, or is taller.

A descriptor has two parts, stacked in one ``(3 + n_samples, n_features)`` array:

- a *profile* (rows 0-2): the mean, the spread and the typical speed of every feature.
  It ignores the phase a clip starts in, which matters for the repetitive moves that fill
  a mocap library (a squat clip cut at the bottom still looks like one cut at the top).
  On the CMU mocap6 takes it finds the right action for 96-100 % of 1-2 s clips.
- a *trajectory* (the other rows): the features resampled to ``n_samples`` steps, compared
  by dynamic time warping (DTW), which adds the order of the poses.

Ranking is two-stage: the profile distance (one matrix operation over the whole library)
keeps a shortlist; profile distance + ``DTW_WEIGHT`` x DTW orders it.

Points of no known marker set (``point_descriptor``) have no limbs to measure, so their
per-frame features are distributions that need no skeleton and no point order: quantiles of
the distances between every two points (of at most ``PAIR_POINTS`` of them, so the cost stays
linear in the points: see ``pair_points``), of each point's height above and horizontal
distance from the points' centroid, and of the points' speeds, all divided by the take's
point spread (``point_scale``). The profile and trajectory are built from them as above,
with as many features as a body descriptor, so one project's vectors share one width; the
service compares a descriptor only with those of its own kind (docs/points.md).
"""

from __future__ import annotations

import numpy as np

from motionlib import _dtw
from motionlib.errors import InputError
from motionlib.features import body_frame_positions, bone_angles
from motionlib.gaps import filled

N_SAMPLES = 32
PROFILE_ROWS = 3
# Speed is measured as the change over a quarter second, so it is of order 1 like the rest.
SPEED_WINDOW_S = 0.25
DTW_WEIGHT = 0.5
# End effectors and mid-limb joints carry what an animator calls the "shape" of a move.
KEY_JOINTS = ("left_wrist", "right_wrist", "left_elbow", "right_elbow", "left_ankle",
              "right_ankle", "left_knee", "right_knee", "head")


def body_scale(positions: np.ndarray, joints: dict[str, int]) -> float:
    """Leg + trunk length (hip-knee-ankle plus root-chest-head), median over frames.

    Bone lengths do not change during a take, so this is a stable size of the performer.
    """
    chain = ("left_hip", "left_knee", "left_ankle")
    parts = [(chain[i], chain[i + 1]) for i in range(2)] + [("root", "chest"), ("chest", "head")]
    lengths = sum(
        np.linalg.norm(positions[:, joints[b]] - positions[:, joints[a]], axis=-1) for a, b in parts
    )
    scale = float(np.median(lengths))
    if not scale > 0:
        raise InputError(f"body scale: the skeleton's leg and trunk have zero length ({scale})")
    return scale


def frame_features(positions: np.ndarray, joints: dict[str, int], scale: float) -> np.ndarray:
    """Per-frame pose features that ignore where the actor stands and which way they face.

    Parameters
    ----------
    positions : (n_frames, n_joints, 3) world joint positions, Y up.
    joints : canonical joint name -> index (``motionlib.canonical_indices``).
    scale : body size in the positions' unit (``body_scale``).

    Returns
    -------
    (n_frames, 8 + 3 * len(KEY_JOINTS)) features: bone angles in radians, then key joint
    positions in the body frame divided by ``scale``.
    """
    angles = bone_angles(positions, joints)
    body = body_frame_positions(positions, joints)[:, [joints[j] for j in KEY_JOINTS]]
    return np.hstack([angles, body.reshape(len(body), -1) / scale])


def resample(x: np.ndarray, n_samples: int = N_SAMPLES) -> np.ndarray:
    """Linear resampling along time (axis 0) to ``n_samples`` evenly spaced steps.

    Parameters
    ----------
    x : (n_frames, n_features), n_frames >= 1.

    Returns
    -------
    (n_samples, n_features)
    """
    x = np.asarray(x, dtype=float)
    if len(x) == 0:
        raise InputError("resample: the clip has no frames")
    if len(x) == 1:
        return np.repeat(x, n_samples, axis=0)
    source = np.linspace(0.0, len(x) - 1, n_samples)
    lo = np.floor(source).astype(int)
    hi = np.minimum(lo + 1, len(x) - 1)
    w = (source - lo)[:, None]
    return (1 - w) * x[lo] + w * x[hi]


def segment_descriptor(positions: np.ndarray, joints: dict[str, int], start: int, stop: int,
                       *, fps: float, scale: float | None = None,
                       n_samples: int = N_SAMPLES) -> np.ndarray:
    """The descriptor of frames ``[start, stop)`` of a take.

    Parameters
    ----------
    positions : (n_frames, n_joints, 3) world joint positions of the whole take.
    joints : canonical joint name -> index.
    start, stop : 0-based frame range, stop exclusive.
    fps : frames per second of the take (speeds are per second).
    scale : body size; computed from the whole take when not given.

    Returns
    -------
    (3 + n_samples, n_features) float32: mean, standard deviation and mean absolute speed
    (change per ``SPEED_WINDOW_S``) of each feature, then the resampled trajectory.
    """
    if not 0 <= start < stop <= len(positions):
        raise InputError(f"segment [{start}, {stop}) is empty or outside the take's "
                         f"{len(positions)} frames")
    if fps <= 0:
        raise InputError(f"fps: must be positive, got {fps}")
    scale = body_scale(positions, joints) if scale is None else scale
    return describe(frame_features(positions[start:stop], joints, scale), fps=fps,
                    n_samples=n_samples)


def describe(features: np.ndarray, *, fps: float, n_samples: int = N_SAMPLES) -> np.ndarray:
    """Profile and trajectory of per-frame features.

    Parameters
    ----------
    features : (n_frames, n_features), n_frames >= 1.
    fps : frames per second (speeds are per ``SPEED_WINDOW_S``).

    Returns
    -------
    (3 + n_samples, n_features) float32: mean, standard deviation and mean absolute speed
    of each feature, then the features resampled to ``n_samples`` steps.
    """
    step = np.abs(np.diff(features, axis=0)) if len(features) > 1 else np.zeros_like(features)
    speed = step.mean(axis=0) * fps * SPEED_WINDOW_S
    profile = np.stack([features.mean(axis=0), features.std(axis=0), speed])
    return np.vstack([profile, resample(features, n_samples)]).astype(np.float32)


# Quantiles per frame of each distribution a bare point descriptor reads; 11 + 8 + 8 + 8
# is the width of a body descriptor (8 bone angles + 3 x 9 key joints), see the docstring.
PAIR_QUANTILES = np.linspace(0.0, 1.0, 11)
HEIGHT_QUANTILES = np.linspace(0.0, 1.0, 8)
REACH_QUANTILES = np.linspace(0.0, 1.0, 8)
SPEED_QUANTILES = np.linspace(0.0, 1.0, 8)
# Most points whose every pair is measured: 2,016 pairs, more than the markers of any body
# marker set have. A take of more points has the pairs of a spread subset of them measured;
# all of them would cost points² per frame (a 1,000-point take: 500,000 pairs a frame, GBs).
PAIR_POINTS = 64
N_POINT_FEATURES = (len(PAIR_QUANTILES) + len(HEIGHT_QUANTILES) + len(REACH_QUANTILES)
                    + len(SPEED_QUANTILES))


def seen_points(points: np.ndarray) -> np.ndarray:
    """The points a bare descriptor reads: those seen in at least one frame, gaps closed.

    Parameters
    ----------
    points : (n_frames, n_points, 3) Y-up positions, NaN where a point was not seen.

    Returns
    -------
    (n_frames, n_seen, 3) float64 (``motionlib.gaps.filled``); at least 2 points.
    """
    points = filled(np.asarray(points, dtype=float))
    points = points[:, ~np.isnan(points).any(axis=(0, 2))]
    if points.shape[1] < 2:
        raise InputError(f"point descriptor: {points.shape[1]} point(s) seen in the take; "
                         "distances need at least 2")
    return points


def point_scale(points: np.ndarray) -> float:
    """Spread of the points: root mean square distance from their centroid, median over
    frames. A size of the performer (and of what they hold) that does not depend on units.

    Parameters
    ----------
    points : (n_frames, n_points, 3) without gaps (``seen_points``).
    """
    centred = points - points.mean(axis=1, keepdims=True)
    scale = float(np.median(np.sqrt((centred ** 2).sum(axis=-1).mean(axis=1))))
    if not scale > 0:
        raise InputError(f"point scale: the points have no spread ({scale})")
    return scale


def point_frame_features(points: np.ndarray, scale: float, *, fps: float) -> np.ndarray:
    """Per-frame features of points without known body parts.

    Parameters
    ----------
    points : (n_frames, n_points, 3) Y-up positions without gaps (``seen_points``).
    scale : ``point_scale`` of the whole take, in the points' unit.
    fps : frames per second (speeds are the change over ``SPEED_WINDOW_S``).

    Returns
    -------
    (n_frames, N_POINT_FEATURES) quantiles of: the distance between every two points (of
    ``pair_points``), each point's height above the centroid, its horizontal distance from
    the centroid, and its speed, divided by ``scale``. None depends on where the points
    stand, which way they face, their unit or their order. Time and memory are linear in
    the points.
    """
    centred = points - points.mean(axis=1, keepdims=True)
    some = points[:, pair_points(centred)]
    i, j = np.triu_indices(some.shape[1], 1)
    pairs = np.linalg.norm(some[:, i] - some[:, j], axis=-1)
    height = centred[..., 1]
    reach = np.hypot(centred[..., 0], centred[..., 2])
    if len(points) > 1:
        moved = np.linalg.norm(np.diff(points, axis=0), axis=-1)
        moved = np.vstack([moved, moved[-1:]]) * fps * SPEED_WINDOW_S
    else:
        moved = np.zeros(points.shape[:2])
    parts = [(pairs, PAIR_QUANTILES), (height, HEIGHT_QUANTILES), (reach, REACH_QUANTILES),
             (moved, SPEED_QUANTILES)]
    return np.hstack([np.quantile(x, q, axis=1).T for x, q in parts]) / scale


def pair_points(centred: np.ndarray) -> np.ndarray:
    """Indices of the points whose pairwise distances a bare descriptor measures: all of
    them up to ``PAIR_POINTS``, else ``PAIR_POINTS`` spread evenly over the points ranked
    by their mean height above the centroid (then their mean horizontal distance from it).

    The ranking depends on nothing a descriptor ignores (placement, heading, unit, point
    order), so neither does the subset.

    Parameters
    ----------
    centred : (n_frames, n_points, 3) points minus their centroid per frame, Y up.
    """
    n = centred.shape[1]
    if n <= PAIR_POINTS:
        return np.arange(n)
    height = centred[..., 1].mean(axis=0)
    reach = np.hypot(centred[..., 0], centred[..., 2]).mean(axis=0)
    ranked = np.lexsort((reach, height))
    return ranked[np.linspace(0, n - 1, PAIR_POINTS).round().astype(int)]


def point_descriptor(points: np.ndarray, start: int, stop: int, *, fps: float,
                     scale: float | None = None, n_samples: int = N_SAMPLES) -> np.ndarray:
    """The descriptor of frames ``[start, stop)`` of a take of bare points.

    Parameters
    ----------
    points : (n_frames, n_points, 3) Y-up positions of the whole take without gaps
        (``seen_points``).
    start, stop : 0-based frame range, stop exclusive.
    fps : frames per second of the take.
    scale : ``point_scale``; computed from the whole take when not given.

    Returns
    -------
    (3 + n_samples, N_POINT_FEATURES) float32, as ``segment_descriptor``.
    """
    if not 0 <= start < stop <= len(points):
        raise InputError(f"segment [{start}, {stop}) is empty or outside the take's "
                         f"{len(points)} frames")
    if fps <= 0:
        raise InputError(f"fps: must be positive, got {fps}")
    scale = point_scale(points) if scale is None else scale
    return describe(point_frame_features(points[start:stop], scale, fps=fps), fps=fps,
                    n_samples=n_samples)


def dtw_distance(a: np.ndarray, b: np.ndarray, *, band: float = 0.25) -> float:
    """Dynamic time warping distance between two descriptors.

    Parameters
    ----------
    a : (n, n_features), b : (m, n_features)
    band : Sakoe-Chiba band as a share of the longer length; a step may drift at most
        this far from the diagonal (keeps a squat from matching a squat-then-stand).

    Returns
    -------
    Sum of Euclidean frame distances along the best warping path divided by ``n + m``
    (so it is comparable across lengths); ``inf`` if the band admits no path.
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    n, m = len(a), len(b)
    cost = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=-1))
    width = max(int(np.ceil(band * max(n, m))), abs(n - m))
    acc = np.full((n + 1, m + 1), np.inf)
    acc[0, 0] = 0.0
    for i in range(1, n + 1):
        centre = i * m / n
        for j in range(max(1, int(centre) - width), min(m, int(centre) + width) + 1):
            acc[i, j] = cost[i - 1, j - 1] + min(acc[i - 1, j - 1], acc[i - 1, j], acc[i, j - 1])
    return float(acc[n, m] / (n + m))


def dtw_distances(a: np.ndarray, bs: np.ndarray, *, band: float = 0.25) -> np.ndarray:
    """``dtw_distance(a, b)`` for every ``b`` in ``bs`` at once (the same numbers, summed in
    another order, so equal up to rounding).

    Parameters
    ----------
    a : (n, n_features)
    bs : (n_items, m, n_features), all of one length ``m``.

    Returns
    -------
    (n_items,) distances, computed by ``motionlib._dtw`` (C): a search ranks its whole
    shortlist this way on every request, and the recursion has no array form that
    numpy runs in less than milliseconds.
    """
    a = np.ascontiguousarray(a, dtype=np.float64)
    bs = np.ascontiguousarray(bs, dtype=np.float64)
    n, m = len(a), bs.shape[1]
    if a.ndim != 2 or bs.ndim != 3 or bs.shape[2] != a.shape[1] or not n or not m:
        raise InputError(f"dtw: expected (n, f) and (items, m, f) descriptors, got shapes "
                         f"{a.shape} and {bs.shape}")
    width = max(int(np.ceil(band * max(n, m))), abs(n - m))
    out = np.empty(len(bs))
    _dtw.distances(a, bs, n, m, a.shape[1], len(bs), width, out)
    return out


def descriptor_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Profile distance + ``DTW_WEIGHT`` x DTW distance of the trajectories."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    profile = float(np.linalg.norm(a[:PROFILE_ROWS] - b[:PROFILE_ROWS]))
    return profile + DTW_WEIGHT * dtw_distance(a[PROFILE_ROWS:], b[PROFILE_ROWS:])


def shortlist_by_profile(query: np.ndarray, profiles: np.ndarray, n: int) -> np.ndarray:
    """Indices of the ``n`` profiles nearest to ``query``'s, nearest first.

    Parameters
    ----------
    query : (PROFILE_ROWS or more, n_features) descriptor or profile.
    profiles : (n_items, PROFILE_ROWS, n_features) profiles (or whole descriptors).
    """
    profiles = np.asarray(profiles, dtype=float)[:, :PROFILE_ROWS]
    diff = (profiles - np.asarray(query, dtype=float)[None, :PROFILE_ROWS]).reshape(len(profiles), -1)
    return np.argsort(np.einsum("ij,ij->i", diff, diff), kind="stable")[:n]


def rank_similar(query: np.ndarray, library: np.ndarray, *, k: int = 10,
                 shortlist: int = 50) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` library descriptors that move most like ``query``.

    Parameters
    ----------
    query : (3 + n_samples, n_features) descriptor.
    library : (n_items, 3 + n_samples, n_features) descriptors of the same shape.
    k : how many to return.
    shortlist : how many profile-nearest items the full distance re-ranks.

    Returns
    -------
    indices : (min(k, n_items),) into ``library``, most similar first.
    distances : their ``descriptor_distance``.
    """
    library = np.asarray(library, dtype=float)
    query = np.asarray(query, dtype=float)
    if library.ndim != 3 or library.shape[1:] != query.shape:
        raise InputError(f"library: expected (n, {', '.join(map(str, query.shape))}) "
                         f"descriptors, got shape {library.shape}")
    if k < 1:
        raise InputError(f"k: must be at least 1, got {k}")
    keep = shortlist_by_profile(query, library, max(shortlist, k))
    profile = np.array([float(np.linalg.norm(query[:PROFILE_ROWS] - library[i, :PROFILE_ROWS]))
                        for i in keep])
    fine = profile + DTW_WEIGHT * dtw_distances(query[PROFILE_ROWS:], library[keep, PROFILE_ROWS:])
    order = np.argsort(fine, kind="stable")[:k]
    return keep[order], fine[order]
