"""Comments on a review: threads pinned to a frame, a cut or a segment of one annotator's
review, read by that annotator and the project's reviewers and admins.

Who may read which thread is ``segmentation.queries.comments``; writing one is
``segmentation.services.comments``.
"""

from django.conf import settings
from django.db import models
from django.utils import timezone

from segmentation.models.reviews import Cut, Review

ANCHORS = (("frame", "Frame"), ("cut", "Cut"), ("segment", "Segment"))


class Comment(models.Model):
    """One comment, or (``parent`` set) a reply in its thread.

    A thread starts on one anchor: a frame (stays on that frame), a cut (follows the cut
    when it is moved) or a segment (the segment that starts at ``cut``, null for the first
    one; it follows that cut like the segment's label does). ``frame`` is the anchor's frame
    when the comment was written, shown when the cut has gone. Replies carry their thread's
    anchor. Comments are not review edits: they do not move the review's version, so a
    reviewer's remark never makes the annotator's next edit stale.
    """

    review = models.ForeignKey(Review, models.CASCADE, related_name="comments")
    author = models.ForeignKey(settings.AUTH_USER_MODEL, models.SET_NULL, null=True, related_name="+")
    parent = models.ForeignKey("self", models.CASCADE, null=True, blank=True, related_name="replies")
    anchor = models.CharField(max_length=10, choices=ANCHORS, default="frame")
    cut = models.ForeignKey(Cut, models.SET_NULL, null=True, blank=True, related_name="+")
    frame = models.PositiveIntegerField()
    text = models.TextField(max_length=2000)
    created_at = models.DateTimeField(default=timezone.now)
    resolved_at = models.DateTimeField(null=True, blank=True)
    resolved_by = models.ForeignKey(settings.AUTH_USER_MODEL, models.SET_NULL, null=True,
                                    blank=True, related_name="+")

    class Meta:
        ordering = ["id"]
        indexes = [models.Index(fields=["review", "id"], name="comment_review")]

    def __str__(self):
        return f"comment {self.pk} on review {self.review_id} at {self.frame}"

    def anchor_frame(self):
        """Where the thread is now: its cut's frame for a cut or a segment that starts at
        a cut still kept, else the frame it was written at (0 for the first segment)."""
        if self.anchor != "frame" and self.cut is not None and self.cut.fate != "deleted":
            return self.cut.frame
        return self.frame
