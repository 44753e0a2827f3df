"""Motion descriptors of library segments (``motionlib.similarity``), stored on their rows
so that similar clips and label suggestions never re-read takes."""

import logging
from types import SimpleNamespace

import numpy as np
from django.db.models import Q

import motionlib
from motionlib import markersets, similarity
from segmentation.errors import Invalid
from segmentation.files import storage
from segmentation.models import LibrarySegment

log = logging.getLogger(__name__)


def capture_joints(capture):
    """Canonical joint indices of a capture's skeleton, or None if it cannot be mapped."""
    names = (capture.skeleton or {}).get("joints") or []
    try:
        return motionlib.canonical_indices(SimpleNamespace(names=list(names)))
    except ValueError:
        return None


def point_marker_set(capture):
    """The marker set of a point capture (``motionlib.markersets``), else None."""
    skeleton = capture.skeleton or {}
    return skeleton.get("marker_set") if skeleton.get("kind") == "points" else None


def is_bare_points(capture):
    """True for a point capture of no known marker set (described by its points alone)."""
    skeleton = capture.skeleton or {}
    return skeleton.get("kind") == "points" and skeleton.get("marker_set") is None


def same_kind(capture):
    """Q of the library segments whose descriptors may be compared with ``capture``'s.

    A body descriptor (a skeleton's joints, or a known marker set's body parts) and a bare
    point descriptor have the same width but measure different things
    (``motionlib.similarity``), so each is compared only with its own kind.
    """
    return of_kind(is_bare_points(capture))


def of_kind(bare_points):
    """Q of the library segments described by their bare points (True) or as a body."""
    if bare_points:
        return Q(capture__skeleton__kind="points", capture__skeleton__marker_set=None)
    # Not the negation of the above: a JSON key a skeleton lacks compares as NULL, and NOT
    # NULL keeps no row.
    return (~Q(capture__skeleton__has_key="kind")
            | Q(capture__skeleton__marker_set__in=sorted(markersets.PARTS)))


def body_positions(capture):
    """``(positions, joints)`` a capture's body descriptors are computed from, or None
    when it has no stored positions or no body parts are known.

    A skeleton's stored joint positions as they are; a point capture's body parts from its
    marker set (``markersets.body_parts``, gaps closed for this only); points of no known
    set have none (``Describer`` describes them by their points). Positions as stored
    (float32) for a skeleton. OSError / ValueError when the stored positions cannot be read.
    """
    if not capture.positions:
        return None
    if (capture.skeleton or {}).get("kind") == "points":
        marker_set = point_marker_set(capture)
        if marker_set is None:
            return None
        positions = np.asarray(storage.load_npy(capture.positions), dtype=float)
        return markersets.body_parts(capture.skeleton["joints"], positions, marker_set)
    joints = capture_joints(capture)
    if joints is None:
        return None
    return storage.load_npy(capture.positions), joints


class Describer:
    """The descriptors of spans of one capture: its positions are read once.

    Body parts when the capture has them (``body_positions``:
    ``similarity.segment_descriptor``); the points themselves for a point capture of no
    known marker set (``similarity.point_descriptor``). ``usable`` is False when neither
    applies. OSError / ValueError when the stored positions cannot be read.
    """

    def __init__(self, capture):
        self.fps = capture.fps
        self.joints = self.points = None
        if is_bare_points(capture) and capture.positions:
            self.points = similarity.seen_points(storage.load_npy(capture.positions))
            self.scale = similarity.point_scale(self.points)
            return
        body = body_positions(capture)
        if body is not None:
            self.points, self.joints = body
            self.scale = similarity.body_scale(np.asarray(self.points, dtype=float), self.joints)

    @property
    def usable(self):
        return self.points is not None

    def __call__(self, start, stop):
        """The float32 descriptor of frames ``[start, stop)``."""
        frames = np.asarray(self.points[start:stop], dtype=float)
        if self.joints is None:
            return similarity.point_descriptor(frames, 0, len(frames), fps=self.fps,
                                               scale=self.scale)
        return similarity.segment_descriptor(frames, self.joints, 0, len(frames), fps=self.fps,
                                             scale=self.scale)


def descriptors(capture, spans):
    """The float32 descriptor of each ``(start, stop)`` span of a capture (``Describer``),
    or Nones when it cannot be described."""
    try:
        describe = Describer(capture)
        if not describe.usable:
            return [None] * len(spans)
        return [describe(start, stop) for start, stop in spans]
    except (OSError, ValueError) as exc:
        # A lost positions file must not stop a review from being submitted; the segments
        # are still listed and exported, only similarity has nothing to go on.
        log.warning("no motion descriptors for capture %s: %s", capture.pk, exc)
        return [None] * len(spans)


def store_descriptor(segment, descriptor):
    if descriptor is not None:
        segment.descriptor = descriptor.astype("<f4").tobytes()
        segment.descriptor_shape = list(descriptor.shape)
        segment.profile = descriptor[: similarity.PROFILE_ROWS].astype("<f4").tobytes()


def load_descriptors(ids):
    """(len(ids), rows, cols) full descriptors of the given segments, in order (one query)."""
    found = {pk: (blob, shape) for pk, blob, shape in LibrarySegment.objects.filter(pk__in=ids)
             .values_list("id", "descriptor", "descriptor_shape")}
    return np.stack([np.frombuffer(bytes(found[pk][0]), dtype="<f4").reshape(found[pk][1])
                     for pk in ids])


def profile_pool(segments, n_features):
    """(ids, (n, PROFILE_ROWS, n_features) profiles) of ``segments`` (a values_list of
    id, profile)."""
    ids, profiles = [], []
    for pk, blob in segments:
        ids.append(pk)
        profiles.append(np.frombuffer(bytes(blob), dtype="<f4").reshape(similarity.PROFILE_ROWS, -1))
    if profiles and profiles[0].shape[1] != n_features:
        raise Invalid(f"library descriptors have {profiles[0].shape[1]} features, the query "
                      f"{n_features}; rebuild the library")
    return ids, np.stack(profiles) if profiles else np.zeros((0, similarity.PROFILE_ROWS, n_features))
