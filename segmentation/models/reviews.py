"""Reviews: one annotator's cuts of one capture, the labels of its segments, and the
audit log of every action."""

from django.conf import settings
from django.db import models
from django.db.models import Q
from django.utils import timezone

from segmentation.models.captures import Capture, DetectionRun
from segmentation.models.projects import Label


class Review(models.Model):
    """One annotator's work on one capture, started from a run's candidates.

    Every write is conditional on ``version`` (see ``services``): a write based on a stale
    version is refused instead of merged.
    """

    # "returned": a reviewer sent a submitted review back with ``return_comment``; it
    # takes edits again and counts nowhere until it is submitted again.
    STATUSES = (("in_progress", "In progress"), ("submitted", "Submitted"), ("returned", "Returned"))
    EDITABLE = ("in_progress", "returned")

    capture = models.ForeignKey(Capture, models.CASCADE, related_name="reviews")
    annotator = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="reviews")
    run = models.ForeignKey(DetectionRun, models.SET_NULL, null=True, blank=True)
    status = models.CharField(max_length=20, choices=STATUSES, default="in_progress")
    version = models.PositiveIntegerField(default=1)
    created_at = models.DateTimeField(default=timezone.now)
    updated_at = models.DateTimeField(default=timezone.now)
    submitted_at = models.DateTimeField(null=True, blank=True)
    # Bounded like every free-text field (segmentation.limits): it is shown in the
    # annotator's queue and review answers.
    return_comment = models.TextField(blank=True, max_length=2000)
    returned_at = models.DateTimeField(null=True, blank=True)

    class Meta:
        ordering = ["id"]
        constraints = [
            models.UniqueConstraint(fields=["capture", "annotator"], name="one_review_per_annotator")
        ]

    def __str__(self):
        return f"{self.annotator} on {self.capture}"

    def kept_cuts(self):
        """Cuts that split the take (everything not deleted), in frame order."""
        return [c for c in self.cuts.all() if c.fate != "deleted"]

    def kept_frames(self):
        """``[(cut id, frame)]`` of the kept cuts in frame order, read as plain values: a
        one-hour take has thousands of cuts, and every edit asks."""
        return list(self.cuts.exclude(fate="deleted").order_by("frame", "id").values_list("id", "frame"))

    def segments(self, kept=None, label="label__name"):
        """Intervals between kept cuts: list of (index, start, stop, label name or None),
        or the label's id with ``label="label_id"``.

        A segment's label is stored against the cut that starts it (no cut for the
        first segment), so labels follow their cut when it is moved. ``kept`` is
        ``kept_frames()`` when the caller has read it already.
        """
        kept = self.kept_frames() if kept is None else kept
        labels = dict(self.segment_labels.filter(label__isnull=False).values_list("cut_id", label))
        starts = [(None, 0)] + kept
        stops = [frame for _, frame in kept] + [self.capture.n_frames or 0]
        return [
            (index, start, stop, labels.get(cut_id))
            for index, ((cut_id, start), stop) in enumerate(zip(starts, stops, strict=True))
        ]

    def segment_start_cut(self, index):
        """The cut that starts segment ``index`` (None for the first); IndexError if none."""
        kept = self.kept_frames()
        if index < 0 or index > len(kept):
            raise IndexError(index)
        return self.cuts.get(pk=kept[index - 1][0]) if index else None


class Cut(models.Model):
    ORIGINS = (("candidate", "Candidate"), ("inserted", "Inserted"))
    FATES = (
        ("pending", "Pending"),
        ("accepted", "Accepted"),
        ("moved", "Moved"),
        ("deleted", "Deleted"),
    )

    review = models.ForeignKey(Review, models.CASCADE, related_name="cuts")
    origin = models.CharField(max_length=20, choices=ORIGINS)
    fate = models.CharField(max_length=20, choices=FATES, default="pending")
    candidate_frame = models.IntegerField(null=True, blank=True)
    frame = models.IntegerField()
    confidence = models.FloatField(null=True, blank=True)

    class Meta:
        ordering = ["frame", "id"]

    def __str__(self):
        return f"cut at {self.frame} ({self.fate})"

    def as_json(self):
        return {"frame": self.frame, "fate": self.fate}


class SegmentLabel(models.Model):
    """The label of the segment that starts at ``cut`` (null cut: the first segment)."""

    review = models.ForeignKey(Review, models.CASCADE, related_name="segment_labels")
    cut = models.ForeignKey(Cut, models.CASCADE, null=True, blank=True, related_name="+")
    label = models.ForeignKey(Label, models.SET_NULL, null=True, blank=True)

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["review", "cut"], name="one_label_per_segment"),
            models.UniqueConstraint(
                fields=["review"], condition=Q(cut__isnull=True), name="one_first_segment_label"
            ),
        ]

    def __str__(self):
        return f"{self.label} from {self.cut or 'the start'}"


class ReviewEvent(models.Model):
    """Audit log: one row per review action, with the state before and after."""

    review = models.ForeignKey(Review, models.CASCADE, related_name="events")
    user = models.ForeignKey(settings.AUTH_USER_MODEL, models.SET_NULL, null=True, related_name="+")
    action = models.CharField(max_length=30)
    cut = models.ForeignKey(Cut, models.SET_NULL, null=True, blank=True, related_name="+")
    before = models.JSONField(null=True, blank=True)
    after = models.JSONField(null=True, blank=True)
    created_at = models.DateTimeField(default=timezone.now)

    class Meta:
        ordering = ["id"]

    def __str__(self):
        return f"{self.action} by {self.user}"
