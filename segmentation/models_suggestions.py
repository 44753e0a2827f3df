"""Stored label suggestions, shared by every web and worker process.

- ``LabelSuggestion``: the suggested label of one span of a capture, computed against
  one state of one pool of library segments (``suggestions.pool_key``: everything, gold
  only, or gold plus one annotator's own). Annotators whose pools are the same share the
  rows; a row of an older state of a pool is stale and never read.
- ``SuggestionRequest``: one per (capture, annotator): when suggestions were last asked
  of a worker and when that worker finished, so that twenty page loads send one job.

See ``segmentation.suggestions``.
"""

from django.conf import settings
from django.db import models
from django.utils import timezone

from segmentation.models import Capture


class LabelSuggestion(models.Model):
    capture = models.ForeignKey(Capture, models.CASCADE, related_name="+")
    # ``suggestions.pool_key``: which segments the label came from, and their state.
    pool = models.CharField(max_length=100)
    start = models.PositiveIntegerField()
    stop = models.PositiveIntegerField()
    # "" when nothing in the pool can name the span (no descriptor, empty pool).
    label_name = models.CharField(max_length=100, blank=True)

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["capture", "pool", "start", "stop"],
                                    name="one_suggestion_per_span")
        ]

    def __str__(self):
        return f"{self.label_name or '-'} for {self.start}-{self.stop} of {self.capture_id}"


class SuggestionRequest(models.Model):
    capture = models.ForeignKey(Capture, models.CASCADE, related_name="+")
    annotator = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="+")
    asked_at = models.DateTimeField(null=True, blank=True)
    done_at = models.DateTimeField(null=True, blank=True)
    created_at = models.DateTimeField(default=timezone.now)

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["capture", "annotator"], name="one_suggestion_request")
        ]

    def __str__(self):
        return f"suggestions for {self.annotator_id} on {self.capture_id}"
