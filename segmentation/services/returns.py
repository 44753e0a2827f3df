"""A reviewer returns a submitted review to its annotator, with a comment."""

from django.db import transaction
from django.db.models import F
from django.utils import timezone

from segmentation.errors import Invalid, ReviewClosed
from segmentation.limits import check_text, text_limit
from segmentation.models import Review, ReviewEvent
from segmentation.services.library import on_review_submitted


def do_return_review(review, reviewer, comment):
    """Send a submitted review back to its annotator with a comment.

    It leaves agreement and the library at once (they use submitted reviews only) and
    takes edits again until the annotator resubmits.
    """
    comment = (comment or "").strip()
    if not comment:
        raise Invalid("comment: say what the annotator should change")
    check_text("comment", comment, text_limit(Review, "return_comment"))
    with transaction.atomic():
        now = timezone.now()
        updated = Review.objects.filter(pk=review.pk, status="submitted").update(
            status="returned", return_comment=comment, returned_at=now,
            version=F("version") + 1, updated_at=now)
        review.refresh_from_db()
        if not updated:
            raise ReviewClosed(f"review {review.pk} is {review.get_status_display().lower()}; "
                               "only a submitted review can be returned")
        ReviewEvent.objects.create(review=review, user=reviewer, action="return",
                                   before={"status": "submitted"},
                                   after={"status": "returned", "comment": comment})
        # Rebuilds the capture's agreement and library rows from its submitted reviews.
        on_review_submitted(review)
    return review
