"""The clip library's rows: labelled segments of submitted reviews and gold versions.

Segments become ``LibrarySegment`` rows when a review is submitted or a gold version is
saved (``refresh_capture_library`` rebuilds one capture's rows: agreement values change
whenever another review of the capture comes in). Each row carries its motion descriptor
(``segmentation.similar.descriptors``), so "find similar" and label suggestions never
re-read takes. The rows of a take of points or of a long take are built and described by a
worker (``build_library``), never in the request (``built_in_request``).
"""

import numpy as np
from django.conf import settings
from django.db import transaction

from motionlib.agreement import label_codes, segment_support
from segmentation import workers
from segmentation.models import Adjudication, Capture, LibrarySegment, Review
from segmentation.services import agreement, attributes
from segmentation.similar import updates
from segmentation.similar.descriptors import descriptors, store_descriptor


def refresh_capture_library(capture):
    """Rebuild a capture's library rows from its submitted reviews and gold version, here
    for a take ``built_in_request`` allows, else by a worker (``build_library``) once the
    caller's transaction commits. Returns the rows built here (none when a worker will).

    Only labelled segments enter the library, each with its label's id (a rename shows on
    it without a rebuild). An annotator's segment carries the share of the other
    annotators' frames that agree with its label; a gold segment the share of all
    annotators' frames. Annotators' segments of a capture with gold are superseded.
    """
    if not built_in_request(capture):
        transaction.on_commit(lambda: workers.send(
            "refresh_library", capture.pk,
            then="its library rows wait for the capture's next submit or gold save"))
        return []
    rows, _ = _rows(capture)
    for segment, descriptor in zip(rows, descriptors(capture, [(r.start, r.stop) for r in rows]),
                                   strict=True):
        store_descriptor(segment, descriptor)
    with transaction.atomic():
        _replace(capture, rows)
    return rows


def built_in_request(capture):
    """Whether the request that submits a review (or saves gold) builds the capture's
    library rows itself: only for a take of joints of at most CUTROOM_DESCRIBE_INLINE joint
    positions. Describing a take of points, or a long one, costs seconds and hundreds of MB
    (a 1,000-point take 18.6 s and 2.94 GB before descriptors were linear in points), which
    on SQLite would hold the database's write lock all along; a worker does it instead."""
    points = (capture.skeleton or {}).get("kind") == "points"
    positions = (capture.n_joints or 0) * (capture.n_frames or 0)
    return not points and positions <= settings.CUTROOM_DESCRIBE_INLINE


def build_library(capture_id):
    """The worker's ``refresh_capture_library``: build and describe a capture's rows
    outside any transaction, then put them in place in a short one, unless a submit, a
    return or a gold save changed what they come from meanwhile (its own job builds them
    then). Returns the number of rows stored, or None if none were (gone, or changed)."""
    capture = Capture.objects.filter(pk=capture_id).first()
    if capture is None:
        return None
    rows, sources = _rows(capture)
    for segment, descriptor in zip(rows, descriptors(capture, [(r.start, r.stop) for r in rows]),
                                   strict=True):
        store_descriptor(segment, descriptor)
    with transaction.atomic():
        Capture.objects.select_for_update().filter(pk=capture_id).first()
        if _sources(capture) != sources:
            return None
        _replace(capture, rows)
    return len(rows)


def _sources(capture):
    """What a capture's rows are built from: its submitted reviews and gold, by version."""
    reviews = Review.objects.filter(capture=capture, status="submitted").order_by("id")
    gold = Adjudication.objects.filter(capture=capture).values_list("pk", "version").first()
    return list(reviews.values_list("pk", "version")), gold


def _replace(capture, rows):
    LibrarySegment.objects.filter(capture=capture).delete()
    LibrarySegment.objects.bulk_create(rows, batch_size=500)
    attributes.store_library_values(capture, rows)
    updates.schedule_update(capture.project_id)


def _rows(capture):
    """The capture's unsaved library rows, and the sources (``_sources``) they are of."""
    # Read first: a submit between this and the reviews below makes the worker's rows
    # differ from their sources at its check, so it leaves them to that submit's job.
    sources = _sources(capture)
    reviews = agreement.submitted_reviews(capture)
    gold = Adjudication.objects.filter(capture=capture).first()
    lists = [agreement.review_segments(r, label="label_id") for r in reviews]
    if gold:
        lists.append(gold.label_segments())
    codes, _ = label_codes(lists, capture.n_frames)
    n = len(reviews)
    rows = []
    for row, segments in enumerate(lists):
        review = reviews[row] if row < n else None
        for start, stop, label_id in segments:
            if label_id is None or stop <= start:
                continue
            support = (segment_support(codes[:n], row, start, stop) if review
                       else _gold_support(codes, n, start, stop))
            rows.append(LibrarySegment(
                project_id=capture.project_id, capture=capture, review=review,
                annotator_id=review.annotator_id if review else None, is_gold=review is None,
                superseded=bool(gold) and review is not None, label_id=label_id,
                start=start, stop=stop, duration=(stop - start) / capture.fps,
                agreement=agreement.finite(support)))
    return rows, sources


def describe_library(capture_id):
    """The worker's half of ``refresh_capture_library`` for a long capture: describe its
    rows that lack descriptors and put them back described.

    Computed outside any transaction; then, in one, the rows are replaced by described
    copies (new ids, as every refresh makes, so the similar index's reading of newer rows
    finds them), unless a newer refresh replaced them meanwhile (it sends its own job).
    Returns the number of rows described.
    """
    capture = Capture.objects.filter(pk=capture_id).first()
    if capture is None:
        return 0
    rows = list(LibrarySegment.objects.filter(capture=capture, descriptor__isnull=True))
    found = descriptors(capture, [(r.start, r.stop) for r in rows]) if rows else []
    for segment, descriptor in zip(rows, found, strict=True):
        store_descriptor(segment, descriptor)
    with transaction.atomic():
        ids = [r.pk for r in rows]
        carried = attributes.library_values(ids)  # read before the delete takes them along
        _, deleted = LibrarySegment.objects.filter(pk__in=ids).delete()  # with their values
        if deleted.get(LibrarySegment._meta.label, 0) != len(ids):
            return 0  # replaced meanwhile; the newer refresh's job describes the new rows
        for row in rows:
            row.pk = None
        LibrarySegment.objects.bulk_create(rows, batch_size=500)
        attributes.copy_library_values(
            carried, {old: row.pk for old, row in zip(ids, rows, strict=True)})
        updates.schedule_update(capture.project_id)
    return len(rows)


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
