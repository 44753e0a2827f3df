"""Who reads which comments (``segmentation.models.comments``).

A review's comments are read by its annotator and by the project's reviewers and admins.
Another annotator of the project does not see them while the capture is being adjudicated:
annotators work blind to one another until a reviewer has saved the capture's gold version
on the adjudication page (an ``Adjudication`` row: the capture is adjudicated). From then
on an annotator who reviewed the capture reads every review's comments on it, as the
discussion of the take, but writes only on their own review. Anybody else, and a
non-member, gets 404: not even that the review has comments is said.
"""

from segmentation.errors import Missing, NotAllowed
from segmentation.models import Adjudication, Comment, Review
from segmentation.queries.access import capture_for


def adjudicated(capture):
    """Whether the capture has a gold version (the adjudication page saved one)."""
    return Adjudication.objects.filter(capture=capture).exists()


def readable_reviews(user, capture):
    """The reviews of ``capture`` whose comments ``user`` reads (a queryset)."""
    reviews = Review.objects.filter(capture=capture)
    if capture.project.can_see_all_reviews(user):
        return reviews
    if adjudicated(capture) and reviews.filter(annotator=user).exists():
        return reviews
    return reviews.filter(annotator=user)


def may_write(user, review):
    """The review's annotator and the project's reviewers and admins comment on it."""
    return review.annotator_id == user.pk or review.capture.project.can_see_all_reviews(user)


def comment_review(user, capture_pk, review_id, write=False):
    """Review ``review_id`` of capture ``capture_pk`` if ``user`` reads its comments (and,
    with ``write``, may add to them); Missing (404) when they may not read them,
    NotAllowed (403) when they read but may not write."""
    capture = capture_for(user, capture_pk)
    review = readable_reviews(user, capture).filter(pk=review_id).select_related("annotator").first()
    if review is None:
        raise Missing("No such review.")
    review.capture = capture
    if write and not may_write(user, review):
        raise NotAllowed("You read the comments of another annotator's review once the capture "
                         "is adjudicated; you comment only on your own review.")
    return review


def threads(reviews):
    """The comments of ``reviews`` (a queryset) with what their answers show, in order."""
    return (Comment.objects.filter(review__in=reviews)
            .select_related("author", "cut", "resolved_by", "review__annotator").order_by("id"))
