"""Assignments: which annotator is asked to review which capture.

An assignment is a request, not a permission on the review itself: unassigning someone
leaves their review (their work) in place. Whether annotators may also review captures
nobody assigned to them is the project's ``annotators_pick_unassigned`` setting.
"""

from django.conf import settings
from django.db import models
from django.utils import timezone


class Assignment(models.Model):
    capture = models.ForeignKey("segmentation.Capture", models.CASCADE, related_name="assignments")
    annotator = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="assignments")
    assigned_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, related_name="+"
    )
    created_at = models.DateTimeField(default=timezone.now)

    class Meta:
        ordering = ["created_at", "id"]
        constraints = [
            models.UniqueConstraint(fields=["capture", "annotator"], name="one_assignment_per_annotator")
        ]

    def __str__(self):
        return f"{self.capture} to {self.annotator}"
