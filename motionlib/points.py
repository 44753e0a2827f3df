"""Point takes: named 3D points (optical markers or tracked joints) over time, with gaps.

A marker file (C3D, Qualisys TSV) or a joint-position file (CSV) has no joint rotations,
only points. :class:`PointTake` is a :class:`~motionlib.take.Take` whose skeleton is the
set of points, without channels; its ``channels`` are the coordinates as stored in the
file and its ``positions`` the same points in the world frame every reader of a take
expects (Y up, the file's length unit). A point not seen in a frame is NaN in both, never
an invented value: gaps are filled only where features are computed
(:func:`filled`), never in what is stored or exported.

Which body parts the points stand for is :mod:`motionlib.markersets`' business.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from motionlib.errors import InputError
from motionlib.gaps import filled
from motionlib.skeleton import Skeleton
from motionlib.take import Take, frame_range

POINT_FORMATS = ("c3d", "tsv", "csv")
UP_AXES = ("y", "z")


@dataclass(eq=False)
class PointTake(Take):
    """A take of points.

    Attributes (besides :class:`~motionlib.take.Take`'s)
    ----------
    channels : ndarray of float64, shape (n_frames, 3 n_points)
        x, y, z of each point in the file's axes and unit; NaN where it was not seen.
    positions : ndarray of float64, shape (n_frames, n_points, 3)
        The same points, Y up (:func:`world`); NaN at the same gaps.
    unit : str
        Length unit as the file names it (``"mm"``, ``"m"``).
    up : {"y", "z"}
        The file's vertical axis.
    first_number : int
        The file's own number of frame 0 (C3D first frame, the TSV ``Frame`` column, the
        CSV ``frame``/``frame_id``), so labels kept in file numbers can be placed.
    marker_set : str or None
        The convention the point names follow (``markersets.identify``), else None.
    """

    unit: str = "mm"
    up: str = "z"
    first_number: int = 0
    marker_set: str | None = None

    @property
    def n_points(self) -> int:
        return self.skeleton.n_joints

    @property
    def point_names(self) -> list[str]:
        return list(self.skeleton.names)

    def slice(self, start: int | None = None, stop: int | None = None) -> PointTake:
        """Frames ``start`` up to ``stop`` (exclusive), their numbers kept."""
        start, stop = frame_range(self.n_frames, start, stop)
        return replace(self, channels=self.channels[start:stop],
                       positions=self.positions[start:stop],
                       first_number=self.first_number + start)


def is_point_take(take) -> bool:
    return isinstance(take, PointTake)


def point_skeleton(names: list[str], parents=None) -> Skeleton:
    """A skeleton of points without channels; ``parents`` (default none, -1 each) are the
    links drawn between them (a forest: a point links to at most one other)."""
    n = len(names)
    parents = [-1] * n if parents is None else list(parents)
    return Skeleton(names=list(names), parents=parents, offsets=np.zeros((n, 3)),
                    channels=[()] * n, rotation_orders=[""] * n, point_set=True)


def world(coordinates: np.ndarray, up: str) -> np.ndarray:
    """Points in the file's axes -> Y up, by a rotation (handedness is kept).

    Parameters
    ----------
    coordinates : (n_frames, n_points, 3)
    up : {"y", "z"}
        For Z up (Vicon, Qualisys) ``(x, y, z) -> (x, z, -y)``, a quarter turn about X.

    Returns
    -------
    (n_frames, n_points, 3) float64, a new array.
    """
    if up not in UP_AXES:
        raise InputError(f"up: expected one of {', '.join(UP_AXES)}, got {up!r}")
    c = np.asarray(coordinates, dtype=np.float64)
    if up == "y":
        return c.copy()
    out = np.empty(c.shape)
    out[..., 0] = c[..., 0]
    out[..., 1] = c[..., 2]
    np.negative(c[..., 1], out=out[..., 2])
    return out


def make_point_take(*, name: str, format: str, fps: float, coordinates: np.ndarray,
                    names: list[str], unit: str, up: str, first_number: int = 0,
                    path=None) -> PointTake:
    """A :class:`PointTake` from coordinates ``(n_frames, n_points, 3)`` in the file's axes;
    the marker set is identified and its links become the skeleton's parents.

    A take in which no point is ever seen is refused (CaptureError): it has no motion to
    segment, show or describe, and every step after would fail on it with a worse reason.
    """
    from motionlib import markersets
    from motionlib.errors import CaptureError

    coordinates = np.asarray(coordinates, dtype=np.float64)
    n_frames = coordinates.shape[0]
    if n_frames and np.isnan(coordinates).all():
        raise CaptureError(f"no point is seen in any of the {n_frames} frames (every "
                           "coordinate is empty or a gap); the take has no motion", path=path)
    marker_set = markersets.identify(names)
    skeleton = point_skeleton(names, markersets.link_parents(names, marker_set))
    positions = world(coordinates, up)
    positions.flags.writeable = False
    return PointTake(name=name, format=format, fps=float(fps), frame_time=1.0 / float(fps),
                     channels=coordinates.reshape(n_frames, -1), skeleton=skeleton,
                     path=None if path is None else str(path), positions=positions,
                     unit=unit, up=up, first_number=int(first_number), marker_set=marker_set)


# Methods that need only a stream of per-frame pose vectors, not body parts, and so run on
# points that follow no known marker set: ``default`` through :class:`BarePoints`, ``ppca``
# on :func:`bare_coordinates` itself.
BARE_POINT_METHODS = frozenset({"default", "ppca"})


@dataclass(eq=False)
class BarePoints:
    """A point take without known body parts, as the default detector reads a take known
    only by channels (``skeleton`` None): one feature vector per frame, here the Y-up
    coordinates of every point seen at least once, gaps closed (:func:`filled`).

    ``channels`` are in degrees because that detector reads channels as angles and turns
    them into radians: stored so, it gets the coordinates back exactly.
    """

    name: str
    fps: float
    channels: np.ndarray
    path: str | None = None
    skeleton: None = None
    positions: None = None
    rest_pose_frame: None = None

    @property
    def n_frames(self) -> int:
        return int(self.channels.shape[0])


def segmenter_input(take, method: str):
    """What segmenter ``method`` is given for ``take``: the take itself, unless it is a
    point take of an unknown marker set: then :class:`BarePoints` for ``default``, the take
    for the other methods that can do without body parts, and for the rest a CaptureError
    saying why they cannot run."""
    from motionlib import markersets
    from motionlib.errors import CaptureError

    if not is_point_take(take) or take.marker_set is not None:
        return take
    if method not in BARE_POINT_METHODS:
        raise CaptureError(
            f"method {method!r} cannot run on this take: it needs body parts (limbs, hips, "
            f"chest), and the points ({', '.join(take.point_names[:8])}"
            f"{', ...' if take.n_points > 8 else ''}) follow no known marker set "
            f"({markersets.KNOWN}); {' and '.join(sorted(BARE_POINT_METHODS))} run on bare "
            "points", path=take.path)
    if method != "default":
        return take
    return BarePoints(name=take.name, fps=take.fps, channels=np.degrees(bare_coordinates(take)),
                      path=take.path)


def bare_coordinates(take: PointTake) -> np.ndarray:
    """(n_frames, 3 n_seen) Y-up coordinates of every point seen at least once, gaps closed
    (:func:`filled`): the pose vector of points without known body parts."""
    points = filled(take.positions)
    seen = ~np.isnan(points[0, :, 0])
    return points[:, seen].reshape(take.n_frames, -1)
