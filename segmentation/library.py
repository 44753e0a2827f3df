"""The clip library: materialised segments, gold versions, exports and similar clips
(label suggestions, which draw on the same rows, are ``segmentation.suggestions``).

Segments become ``LibrarySegment`` rows when a review is submitted or a gold version is
saved (``refresh_capture_library`` rebuilds one capture's rows: agreement values change
whenever another review of the capture comes in). Each row carries its motion descriptor
(``motionlib.similarity``), so "find similar" and label suggestions never re-read takes.
"""

import csv
import io
import itertools
import json
import logging
import re
import zipfile
from pathlib import PurePath
from types import SimpleNamespace

import numpy as np
from django.db import transaction
from django.utils import timezone

import motionlib
from motionlib import similarity
from motionlib.agreement import label_codes, segment_support
from segmentation import agreement, similar_index, storage
from segmentation.models import Adjudication, LibrarySegment
from segmentation.services.captures import read_take

log = logging.getLogger(__name__)

# Similar clips and suggestions search at most this many of a project's recent segments.
SIMILAR_POOL = 20000
# Profile-nearest segments whose full descriptors are compared (DTW) in both searches.
SHORTLIST = 20
MAX_EXPORT_SEGMENTS = 5000


class StaleGold(Exception):
    """A gold version was saved from an old version; ``adjudication`` is the current one."""

    def __init__(self, adjudication):
        super().__init__(
            f"the gold version is at version {adjudication.version}; reload it and redo the change"
        )
        self.adjudication = adjudication


def capture_joints(capture):
    """Canonical joint indices of a capture's skeleton, or None if it cannot be mapped."""
    names = (capture.skeleton or {}).get("joints") or []
    try:
        return motionlib.canonical_indices(SimpleNamespace(names=list(names)))
    except ValueError:
        return None


def descriptors(capture, spans):
    """The float32 descriptor of each ``(start, stop)`` span of a capture, or Nones when
    its skeleton cannot be mapped to body parts."""
    joints = capture_joints(capture) if capture.positions else None
    if joints is None:
        return [None] * len(spans)
    try:
        positions = np.asarray(storage.load_npy(capture.positions), dtype=float)
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
        raise ValueError(f"library descriptors have {profiles[0].shape[1]} features, the query "
                         f"{n_features}; rebuild the library")
    return ids, np.stack(profiles) if profiles else np.zeros((0, similarity.PROFILE_ROWS, n_features))


def refresh_capture_library(capture):
    """Rebuild a capture's library rows from its submitted reviews and gold version.

    Only labelled segments enter the library. An annotator's segment carries the share of
    the other annotators' frames that agree with its label; a gold segment the share of
    all annotators' frames. Annotators' segments of a capture with gold are superseded.
    """
    reviews = agreement.submitted_reviews(capture)
    gold = Adjudication.objects.filter(capture=capture).first()
    lists = [agreement.review_segments(r) for r in reviews]
    if gold:
        lists.append(gold.segments())
    codes, _ = label_codes(lists, capture.n_frames)
    labels = {label.name: label for label in capture.project.labels.all()}
    n = len(reviews)
    rows = []
    for row, segments in enumerate(lists):
        review = reviews[row] if row < n else None
        for start, stop, name in segments:
            if name is None or stop <= start:
                continue
            support = (segment_support(codes[:n], row, start, stop) if review
                       else _gold_support(codes, n, start, stop))
            rows.append(LibrarySegment(
                project_id=capture.project_id, capture=capture, review=review,
                annotator_id=review.annotator_id if review else None, is_gold=review is None,
                superseded=bool(gold) and review is not None, label=labels.get(name),
                label_name=name, start=start, stop=stop, duration=(stop - start) / capture.fps,
                agreement=agreement.finite(support)))
    for segment, descriptor in zip(rows, descriptors(capture, [(r.start, r.stop) for r in rows]),
                                   strict=True):
        store_descriptor(segment, descriptor)
    with transaction.atomic():
        LibrarySegment.objects.filter(capture=capture).delete()
        LibrarySegment.objects.bulk_create(rows, batch_size=500)
        similar_index.schedule_update(capture.project_id)
    return rows


def _gold_support(codes, n_reviews, start, stop):
    """Share of all annotators' frames in [start, stop) that carry the gold label."""
    if n_reviews == 0:
        return float("nan")
    gold = codes[n_reviews, start:stop]
    return float(np.mean(codes[:n_reviews, start:stop] == gold[None, :]))


def on_review_submitted(review):
    """Called by the submit workflow, inside its transaction."""
    capture = review.capture
    agreement.refresh_capture_agreement(capture)
    refresh_capture_library(capture)


def check_gold(capture, cuts, labels):
    """Validated (cuts, labels) of a gold version; ValueError names the bad value."""
    if not isinstance(cuts, list) or not all(isinstance(c, int) and not isinstance(c, bool)
                                             for c in cuts):
        raise ValueError(f"cuts: must be a list of frame numbers, got {cuts!r}")
    for i, frame in enumerate(cuts):
        if not 0 < frame < capture.n_frames:
            raise ValueError(f"cuts: cut {i} at frame {frame} is outside 1..{capture.n_frames - 1}")
        if i and frame <= cuts[i - 1]:
            raise ValueError(f"cuts: cut {i} at frame {frame} is not after the previous cut "
                             f"({cuts[i - 1]}); send cuts in increasing frame order")
    if not isinstance(labels, list) or len(labels) != len(cuts) + 1:
        raise ValueError(f"labels: expected {len(cuts) + 1} labels (one per segment), "
                         f"got {len(labels) if isinstance(labels, list) else repr(labels)}")
    known = set(capture.project.labels.values_list("name", flat=True))
    for i, name in enumerate(labels):
        if name is not None and name not in known:
            raise ValueError(f"labels: segment {i} has label {name!r}, which is not a label of "
                             f"this project ({', '.join(sorted(known))})")
    return cuts, labels


def do_save_gold(capture, user, cuts, labels, version, source_review=None):
    """Create or replace the capture's gold version and rebuild its library rows.

    ``version`` is the gold version the reviewer started from (0 when there was none);
    anything else than the current version is refused with ``StaleGold``.
    """
    cuts, labels = check_gold(capture, cuts, labels)
    if not capture.reviews.filter(status="submitted").exists():
        raise ValueError("capture: a gold version needs at least one submitted review")
    if source_review is not None and source_review.capture_id != capture.pk:
        raise ValueError(f"source_review: review {source_review.pk} is not of this capture")
    with transaction.atomic():
        current = Adjudication.objects.select_for_update().filter(capture=capture).first()
        if (current.version if current else 0) != version:
            raise StaleGold(current) if current else ValueError(
                f"version: there is no gold version yet; send 0, got {version}")
        gold = current or Adjudication(capture=capture, version=0)
        gold.adjudicator, gold.source_review = user, source_review
        gold.cuts, gold.labels = cuts, labels
        gold.version += 1
        gold.updated_at = timezone.now()
        gold.save()
        refresh_capture_library(capture)
        from segmentation.services.adaptation import on_examples_changed

        on_examples_changed(capture.project_id)
    return gold


def slug(text):
    return re.sub(r"[^A-Za-z0-9_]+", "-", str(text)).strip("-") or "untitled"


def file_name(segment):
    """``capture_label_start-stop.bvh`` with safe characters only."""
    stem = PurePath(segment.capture.name).stem
    return f"{slug(stem)}_{slug(segment.label_name)}_{segment.start}-{segment.stop}.bvh"


def bvh_text(take, segment):
    """The segment's frames as BVH with the take's own hierarchy and frame time.

    A cgspeed BVH's added T-pose frame (``take.rest_pose_frame``) is not part of the
    performance, so a clip that starts on or before it starts just after it.
    """
    start = segment.start
    if take.rest_pose_frame is not None and start <= take.rest_pose_frame < segment.stop - 1:
        start = take.rest_pose_frame + 1
    out = io.StringIO()
    motionlib.write_bvh(take, out, start=start, stop=segment.stop)
    return out.getvalue()


def unique_name(name, segment, used):
    """``name``, or with the annotator (then the segment id) added if the archive already
    holds it: two annotators' versions of one range and label would share a name."""
    if name in used:
        stem, dot, ext = name.rpartition(".")
        who = slug(segment.annotator.username) if segment.annotator else "gold"
        name = f"{stem}_{who}{dot}{ext}"
        if name in used:
            name = f"{stem}_{who}_{segment.pk}{dot}{ext}"
    used.add(name)
    return name


def manifest_row(segment, name, fmt="bvh"):
    return {
        "file": name, "format": fmt, "segment": segment.pk, "capture": segment.capture.name,
        "capture_id": segment.capture_id, "start": segment.start, "stop": segment.stop,
        "label": segment.label_name, "gold": segment.is_gold,
        "annotator": segment.annotator.username if segment.annotator else None,
        "agreement": segment.agreement,
    }


class _Sink:
    """A write-only file for ``zipfile``: it collects bytes until ``drain`` hands them out."""

    def __init__(self):
        self.parts = []

    def write(self, data):
        self.parts.append(bytes(data))
        return len(data)

    def flush(self):
        pass

    def drain(self):
        data, self.parts = b"".join(self.parts), []
        return data


def stream_zip(segments, fmt="bvh"):
    """Yield a zip archive of one clip per segment (BVH, FBX or glTF binary: ``fmt``) plus
    ``manifest.csv`` and ``manifest.json``.

    ``segments`` should be ordered by capture so each take is read once; the archive is
    written as it goes (at most one take and one capture's clips are in memory). A take that
    cannot be read any more cannot turn into an error response once streaming has begun: its
    segments are left out and ``errors.txt`` says why.
    """
    sink = _Sink()
    manifest, errors, used = [], [], set()
    with zipfile.ZipFile(sink, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for _, group in itertools.groupby(segments, key=lambda s: s.capture_id):
            group = list(group)
            capture = group[0].capture
            try:
                take = read_take(capture)
                for segment, name, data in _clips(capture, take, group, fmt):
                    name = unique_name(name, segment, used)
                    archive.writestr(name, data)
                    manifest.append(manifest_row(segment, name, fmt))
                    yield sink.drain()
            except ValueError as exc:
                errors.append(f"capture {capture.pk} ({capture.name}): {exc}")
        archive.writestr("manifest.json", json.dumps(manifest, indent=1))
        archive.writestr("manifest.csv", _csv(manifest))
        if errors:
            archive.writestr("errors.txt", "\n".join(errors) + "\n")
    yield sink.drain()


def _clips(capture, take, segments, fmt):
    if fmt == "bvh":
        return ((s, file_name(s), bvh_text(take, s)) for s in segments)
    from segmentation.exports import clip_files

    return clip_files(capture, take, segments, fmt)


def _csv(rows):
    out = io.StringIO()
    fields = ["file", "format", "segment", "capture", "capture_id", "start", "stop", "label", "gold",
              "annotator", "agreement"]
    writer = csv.DictWriter(out, fieldnames=fields)
    writer.writeheader()
    writer.writerows(rows)
    return out.getvalue()


def similar(segment, visible, k=10):
    """The ``k`` visible segments of the same project that move most like ``segment``.

    Segments overlapping it in the same capture are left out (other annotators' versions
    of the same motion), and so are duplicates of one span. Two stages: the profiles
    nearest to the query's pick a shortlist, whose full descriptors are ranked. The
    shortlist comes from the project's vector index (``similar_index``) when it has a
    usable one, else from the profiles of up to ``SIMILAR_POOL`` recent segments.
    Returns ``[(segment, distance)]``, most similar first.
    """
    query = segment.descriptor_array()
    if query is None:
        raise ValueError(f"segment {segment.pk}: its skeleton could not be mapped to body "
                         "parts, so it has no motion descriptor")
    pool = (visible.filter(project_id=segment.project_id, profile__isnull=False)
            .exclude(capture_id=segment.capture_id, start__lt=segment.stop, stop__gt=segment.start))
    n = max(SHORTLIST, k)
    index = similar_index.open_index(segment.project_id)
    short = similar_index.shortlist(index, query, pool, n) if index else None
    if short is None:
        short = exact_shortlist(query, pool, n)
    if not short:
        return []
    # The shortlist's rows, with what the caller shows of them, in one query.
    rows = (LibrarySegment.objects.select_related("capture", "annotator", "label")
            .defer("profile", "capture__skeleton").in_bulk(short))
    short = [pk for pk in short if pk in rows]  # a capture's rows rebuilt meanwhile
    if not short:
        return []
    order, distances = similarity.rank_similar(
        query, np.stack([rows[pk].descriptor_array() for pk in short]), k=k, shortlist=len(short))
    return [(rows[short[i]], float(d)) for i, d in zip(order, distances, strict=True)]


def exact_shortlist(query, pool, n):
    """Ids of the ``n`` profile-nearest segments among the ``SIMILAR_POOL`` most recent of
    ``pool`` (one span counted once, its newest row kept), nearest first."""
    rows = pool.order_by("-id").values_list("id", "capture_id", "start", "stop", "profile")
    seen, unique = set(), []
    for pk, capture_id, start, stop, blob in rows[:SIMILAR_POOL]:
        if (capture_id, start, stop) not in seen:
            seen.add((capture_id, start, stop))
            unique.append((pk, blob))
    ids, profiles = profile_pool(unique, query.shape[1])
    if not ids:
        return []
    return [ids[i] for i in similarity.shortlist_by_profile(query, profiles, n)]
