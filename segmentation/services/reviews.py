"""Reviews: one annotator's cuts and labels on one capture, with an audit log.

Every write is ``_write(review, version)``: one conditional UPDATE that bumps the
version only if the caller saw the current one. Zero rows updated means someone else
wrote first, and the caller gets ``StaleVersion`` with the current review (a 409), so two
clients never silently overwrite each other.
"""

from django.db import IntegrityError, transaction
from django.db.models import F
from django.utils import timezone

from segmentation.errors import Invalid, NotReady, ReviewClosed, StaleVersion
from segmentation.models import Capture, Cut, Review, ReviewEvent, SegmentLabel
from segmentation.services.adaptation import on_examples_changed
from segmentation.services.assignments import check_may_start
from segmentation.services.library import on_review_submitted

FATE_ACTIONS = {"accepted": "accept", "deleted": "delete", "pending": "reset"}


def own_review(capture, user):
    """The user's review of a capture, or None if they have not started one (no write)."""
    review = Review.objects.filter(capture=capture, annotator=user).first()
    if review is None and capture.status != "ready":
        raise NotReady(
            f"capture {capture.pk} is {capture.status}; it can be reviewed once it is ready"
        )
    if review is None:
        # An annotator who may not pick this capture (not assigned to them, in a project
        # that does not allow picking) may not start, so may not open, its review.
        check_may_start(capture, user)
    if review is not None:
        review.capture, review.annotator = capture, user
    return review


def reload(review):
    """Read the review's own columns again, keeping its capture and annotator (a review
    of a long take is written and read on every edit: no query that is not needed)."""
    review.refresh_from_db(fields=["run", "status", "version", "updated_at", "submitted_at"])


def started_review(user, capture_id):
    """The user's review of a capture of one of their projects, read with its capture in
    one query (every edit asks), or None if they have not started one."""
    review = (
        Review.objects.select_related("capture")
        .filter(capture_id=capture_id, annotator=user, capture__in=Capture.objects.visible_to(user))
        .first()
    )
    if review is not None:
        review.annotator = user
    return review


def get_or_create_review(capture, user):
    """The user's review of a capture, started from the latest finished run if new.

    Only writes call this: reading a review never creates one (see ``own_review``).
    """
    review = own_review(capture, user)
    if review:
        catch_up(review)
        return review
    try:
        with transaction.atomic():
            return _create_review(capture, user)
    except IntegrityError:
        # Two first requests raced; the other one created it.
        return Review.objects.get(capture=capture, annotator=user)


def _create_review(capture, user):
    run = capture.latest_finished_run()
    review = Review.objects.create(capture=capture, annotator=user, run=run)
    candidates = run.candidates if run else []
    _add_candidates(review, candidates)
    after = {"run": run.pk if run else None, "candidates": len(candidates)}
    ReviewEvent.objects.create(review=review, user=user, action="create", after=after)
    return review


def _add_candidates(review, candidates, taken=()):
    """Candidate cuts of ``review``, leaving out frames in ``taken`` (kept cuts)."""
    return Cut.objects.bulk_create(
        Cut(review=review, origin="candidate", candidate_frame=c["frame"], frame=c["frame"],
            confidence=c["confidence"])
        for c in candidates if c["frame"] not in taken
    )


def catch_up(review):
    """A review started before detection finished, whose run has finished since but
    missed the hand-over (``do_take_in_candidates``; e.g. both committed at once), takes
    the candidates in before the write. Its version goes up, so the write itself is
    refused as stale and its client reloads: the segment indexes it meant have moved."""
    if review.run_id is None and review.status == "in_progress":
        run = review.capture.latest_finished_run()
        if run is not None:
            with transaction.atomic():
                take_in_candidates(review, run)


def take_in_candidates(review, run):
    """Give a review started before detection finished the candidates of ``run``.

    Runs inside the caller's transaction. The review keeps everything its annotator did
    (a candidate on a frame they already cut is left out) and its version goes up, so a
    page holding the old version reloads instead of overwriting. Returns True if the
    review took them (False if it already had a run or was submitted).
    """
    updated = Review.objects.filter(pk=review.pk, run__isnull=True, status="in_progress").update(
        run=run, version=F("version") + 1, updated_at=timezone.now()
    )
    if not updated:
        return False
    taken = set(review.cuts.exclude(fate="deleted").values_list("frame", flat=True))
    added = _add_candidates(review, run.candidates, taken)
    _log(review, None, "candidates", after={"run": run.pk, "candidates": len(added)})
    reload(review)
    return True


def do_take_in_candidates(run):
    """Called when ``run`` finished: every review of its capture still waiting for
    candidates takes them in. Returns how many did."""
    count = 0
    for review in Review.objects.filter(capture_id=run.capture_id, run__isnull=True,
                                        status="in_progress"):
        with transaction.atomic():
            count += take_in_candidates(review, run)
    return count


def _write(review, version):
    """Claim the next version of ``review`` or raise StaleVersion / ReviewClosed."""
    now = timezone.now()
    updated = Review.objects.filter(pk=review.pk, version=version, status__in=Review.EDITABLE).update(
        version=F("version") + 1, updated_at=now
    )
    if updated and review.version == version:
        # Every write moves the version on: the row is as this object read it, one on.
        review.version, review.updated_at = version + 1, now
        return
    reload(review)
    if updated:
        return
    if review.version != version:
        raise StaleVersion(review)
    raise ReviewClosed(f"review {review.pk} was submitted; it takes no more changes")


def _check_frame(review, frame, moving=None):
    """A cut frame must be inside the take and not on another kept cut."""
    review.capture.check_cut_frame(frame)
    taken = review.cuts.exclude(fate="deleted").filter(frame=frame)
    if moving is not None:
        taken = taken.exclude(pk=moving.pk)
    if taken.exists():
        raise Invalid(f"frame: there is already a cut at frame {frame}")


def _log(review, user, action, cut=None, before=None, after=None):
    ReviewEvent.objects.create(
        review=review, user=user, action=action, cut=cut, before=before, after=after
    )


def do_insert_cut(review, user, frame, version):
    """Add a cut the detector missed; it counts as accepted."""
    with transaction.atomic():
        _write(review, version)
        _check_frame(review, frame)
        cut = Cut.objects.create(review=review, origin="inserted", fate="accepted", frame=frame)
        _log(review, user, "insert", cut, after=cut.as_json())
    return review


def do_change_cut(review, user, cut, version, fate=None, frame=None):
    """Accept, delete or reset a cut (``fate``), or move it to ``frame``."""
    with transaction.atomic():
        _write(review, version)
        cut.refresh_from_db()
        before = cut.as_json()
        if frame is not None:
            _check_frame(review, frame, moving=cut)
            cut.frame = frame
            cut.fate = "moved" if cut.origin == "candidate" else "accepted"
            action = "move"
        else:
            if fate not in FATE_ACTIONS:
                raise Invalid(f"fate: must be accepted, deleted or pending, got {fate!r}")
            if cut.fate == "deleted" and fate != "deleted":
                _check_frame(review, cut.frame, moving=cut)
            cut.fate = fate
            action = FATE_ACTIONS[fate]
        cut.save(update_fields=["frame", "fate"])
        _log(review, user, action, cut, before=before, after=cut.as_json())
    return review


def do_label_segment(review, user, index, label_name, version):
    """Set (or clear, with None) the label of segment ``index``."""
    with transaction.atomic():
        _write(review, version)
        try:
            start_cut = review.segment_start_cut(index)
        except IndexError:
            raise Invalid(f"index: the review has no segment {index}") from None
        label = None
        if label_name is not None:
            label = review.capture.project.labels.filter(name=label_name).first()
            if label is not None and label.retired:
                raise Invalid(f"label: {label_name!r} is retired; pick a label in use")
            if label is None:
                names = ", ".join(review.capture.project.labels.values_list("name", flat=True))
                raise Invalid(f"label: {label_name!r} is not a label of this project ({names})")
        row, _ = SegmentLabel.objects.get_or_create(review=review, cut=start_cut)
        before = {"index": index, "label": row.label.name if row.label else None}
        row.label = label
        row.save(update_fields=["label"])
        _log(review, user, "label", start_cut, before=before, after={"index": index, "label": label_name})
    return review


def do_submit_review(review, user, version):
    with transaction.atomic():
        _write(review, version)
        was = review.status  # as of the write that claimed the version
        now = timezone.now()
        Review.objects.filter(pk=review.pk).update(status="submitted", submitted_at=now)
        review.status, review.submitted_at = "submitted", now
        # A returned review submitted again is a "resubmit" in the audit log.
        action = "resubmit" if was == "returned" else "submit"
        _log(review, user, action, before={"status": was}, after={"status": "submitted"})
        # Materialise the capture's library rows and agreement with the submit itself.
        on_review_submitted(review)
        # The project's cut model learns from the new example once this commits.
        on_examples_changed(review.capture.project_id)
    return review
