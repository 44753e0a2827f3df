"""Reference videos: camera footage recorded beside a take, played in sync with it."""

import uuid

from django.conf import settings
from django.db import models, transaction
from django.db.models.signals import post_delete
from django.dispatch import receiver
from django.utils import timezone

from segmentation.errors import Invalid
from segmentation.models.captures import Capture

# An offset further than a day from the take is a typing slip, not a recording.
MAX_OFFSET_S = 86_400.0


def video_path(video, filename):
    return f"videos/{video.capture.project_id}/{uuid.uuid4().hex}/{filename}"


class ReferenceVideo(models.Model):
    """One video of a capture, stored as uploaded (never transcoded) and checksummed.

    ``offset_s`` places it against the take: the video time shown at take time ``t`` is
    ``t + offset_s`` (so a video started 2 s before the take has ``offset_s = 2``). It is one
    value for everyone who opens the capture. ``duration``, ``fps``, ``codec`` and the size
    come from ffprobe when it was installed at upload, else they are empty.
    """

    capture = models.ForeignKey(Capture, models.CASCADE, related_name="videos")
    uploaded_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, related_name="+"
    )
    name = models.CharField(max_length=255)
    file = models.FileField(upload_to=video_path, max_length=500)
    checksum = models.CharField(max_length=64)
    stored_bytes = models.PositiveBigIntegerField(default=0)
    container = models.CharField(max_length=10)
    codec = models.CharField(max_length=20, blank=True)
    duration = models.FloatField(null=True, blank=True)
    fps = models.FloatField(null=True, blank=True)
    width = models.PositiveIntegerField(null=True, blank=True)
    height = models.PositiveIntegerField(null=True, blank=True)
    offset_s = models.FloatField(default=0.0)
    offset_set_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, blank=True, related_name="+"
    )
    offset_set_at = models.DateTimeField(null=True, blank=True)
    created_at = models.DateTimeField(default=timezone.now)

    class Meta:
        ordering = ["created_at", "id"]
        constraints = [
            models.UniqueConstraint(fields=["capture", "checksum"], name="unique_video_checksum")
        ]

    def __str__(self):
        return f"{self.name} of {self.capture}"

    @staticmethod
    def check_offset(value):
        """``value`` as an offset in seconds; ``Invalid`` names it when it is not one."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise Invalid(f"offset_s: must be a number of seconds, got {value!r:.40}")
        if not -MAX_OFFSET_S <= value <= MAX_OFFSET_S:  # also refuses NaN
            raise Invalid(f"offset_s: must be between -{MAX_OFFSET_S:g} and {MAX_OFFSET_S:g} "
                          f"seconds, got {value!r}")
        return float(value)

    @staticmethod
    def may_manage(project, user):
        """Whether ``user`` may add, align and remove the videos of ``project``'s captures:
        its reviewers and admins. A video and its offset are shared by every review of the
        capture, so they are set by those who see all reviews; annotators watch them."""
        return project.can_see_all_reviews(user)


@receiver(post_delete, sender=ReferenceVideo)
def _delete_stored_file(sender, instance, **kwargs):
    """A video's file goes with its row (its own deletion, its capture's or its project's),
    once the deletion is committed: a rolled-back deletion keeps both."""
    name, storage = instance.file.name, instance.file.storage
    if name:
        transaction.on_commit(lambda: storage.delete(name))
