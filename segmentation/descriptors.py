"""Motion descriptors of library segments (``motionlib.similarity``), stored on their rows
so that similar clips and label suggestions never re-read takes."""

import logging
from types import SimpleNamespace

import numpy as np

import motionlib
from motionlib import markersets, similarity
from segmentation import storage
from segmentation.errors import Invalid
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


def body_positions(capture):
    """``(positions, joints)`` a capture's motion descriptors are computed from, or None
    when it has no stored positions or no body parts are known.

    A skeleton's stored joint positions as they are; a point capture's body parts from its
    marker set (``markersets.body_parts``, gaps closed for this only); points of no known
    set have none. Positions as stored (float32) for a skeleton. OSError / ValueError when
    the stored positions cannot be read.
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


def descriptors(capture, spans):
    """The float32 descriptor of each ``(start, stop)`` span of a capture, or Nones when
    its skeleton (or its points) cannot be mapped to body parts."""
    try:
        body = body_positions(capture)
        if body is None:
            return [None] * len(spans)
        positions, joints = np.asarray(body[0], dtype=float), body[1]
        scale = similarity.body_scale(positions, joints)
        return [
            similarity.segment_descriptor(positions, joints, start, stop, fps=capture.fps, scale=scale)
            for start, stop in spans
        ]
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
