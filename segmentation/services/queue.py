"""Each member's queue: the captures assigned to them and the reviews they started."""

from segmentation.models import Assignment, Review

QUEUE_STATES = ("assigned", "in_progress", "returned", "submitted")


def queue(user, project=None):
    """The user's queue: assigned captures and own reviews, oldest first.

    Each item: capture (id, name, project, duration, n_candidates), state (assigned,
    in_progress, returned, submitted), since (assignment or review creation time),
    the review's id, version and return comment.
    """
    assignments = Assignment.objects.filter(annotator=user).select_related("capture")
    reviews = Review.objects.filter(annotator=user).select_related("capture", "run")
    if project is not None:
        assignments = assignments.filter(capture__project=project)
        reviews = reviews.filter(capture__project=project)
    by_capture = {r.capture_id: r for r in reviews}
    items = {}
    for a in assignments:
        items[a.capture_id] = _item(a.capture, by_capture.get(a.capture_id), a.created_at, True)
    for r in by_capture.values():
        items.setdefault(r.capture_id, _item(r.capture, r, r.created_at, False))
    return sorted(items.values(), key=lambda i: (i["since"], i["capture"]["id"]))


def _item(capture, review, since, assigned):
    run = review.run if review and review.run else capture.latest_finished_run()
    return {
        "capture": {"id": capture.pk, "name": capture.name, "project": capture.project_id,
                    "duration": capture.duration, "n_frames": capture.n_frames,
                    "n_candidates": len(run.candidates) if run else None},
        "state": review.status if review else "assigned",
        "assigned": assigned,
        "since": since,
        "review": None if review is None else {
            "id": review.pk, "version": review.version, "submitted_at": review.submitted_at,
            "return_comment": review.return_comment or None, "returned_at": review.returned_at},
    }
