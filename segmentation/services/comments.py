"""Writing comments on a review: a thread on a frame, a cut or a segment, replies to it,
and resolving it. Who may is ``segmentation.queries.comments``."""

from django.db import transaction
from django.utils import timezone

from segmentation.errors import Invalid
from segmentation.limits import check_text, text_limit
from segmentation.models import Comment


def check_anchor(review, frame=None, cut=None, segment=None, parent=None):
    """``(anchor, cut, frame, parent)`` of a new comment from exactly one of ``frame``
    (a frame of the take), ``cut`` (an id of a kept cut of the review), ``segment`` (an
    index of the review's segments) or ``parent`` (the id of a comment of the review: a
    reply, in that comment's thread). Invalid names the bad field and value."""
    given = [name for name, value in (("frame", frame), ("cut", cut), ("segment", segment),
                                      ("parent", parent)) if value is not None]
    if len(given) != 1:
        raise Invalid("anchor: send exactly one of frame, cut, segment or parent (a reply), "
                      f"got {', '.join(given) or 'none'}")
    if parent is not None:
        thread = review.comments.filter(pk=parent).select_related("cut").first()
        if thread is None:
            raise Invalid(f"parent: comment {parent} is not a comment of this review")
        thread = thread.parent or thread  # a reply to a reply joins the same thread
        return thread.anchor, thread.cut, thread.frame, thread
    if frame is not None:
        n_frames = review.capture.n_frames or 0
        if not 0 <= frame < n_frames:
            raise Invalid(f"frame: must be between 0 and {n_frames - 1}, got {frame}")
        return "frame", None, frame, None
    if cut is not None:
        found = review.cuts.exclude(fate="deleted").filter(pk=cut).first()
        if found is None:
            raise Invalid(f"cut: {cut} is not a kept cut of this review")
        return "cut", found, found.frame, None
    try:
        start = review.segment_start_cut(segment)
    except IndexError:
        raise Invalid(f"segment: the review has no segment {segment}") from None
    return "segment", start, start.frame if start else 0, None


def do_add_comment(review, user, text, **anchor):
    """A new thread on ``review`` or a reply (``parent``); see ``check_anchor``."""
    text = check_text("text", (text or "").strip(), text_limit(Comment, "text"))
    if not text:
        raise Invalid("text: a comment needs some text")
    with transaction.atomic():
        kind, cut, frame, parent = check_anchor(review, **anchor)
        return Comment.objects.create(review=review, author=user, parent=parent, anchor=kind,
                                      cut=cut, frame=frame, text=text)


def do_resolve_comment(comment, user, resolved):
    """Mark a thread resolved (or open again); a reply is resolved with its thread."""
    if comment.parent_id is not None:
        raise Invalid(f"comment: {comment.pk} is a reply; resolve its thread "
                      f"(comment {comment.parent_id})")
    comment.resolved_at = timezone.now() if resolved else None
    comment.resolved_by = user if resolved else None
    comment.save(update_fields=["resolved_at", "resolved_by"])
    return comment
