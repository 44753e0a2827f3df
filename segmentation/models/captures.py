"""Captures (uploaded takes), the detection runs over them, and the assignments of a
capture to the annotators asked to review it."""

import uuid

from django.conf import settings
from django.db import models
from django.utils import timezone

from segmentation.errors import Invalid
from segmentation.models.jobs import ClaimQuerySet, Job, claim_cutoff
from segmentation.models.projects import Project


class CaptureQuerySet(ClaimQuerySet):
    def claim(self, pk, token):
        """Claim a capture's job; a conversion (Blender reading an FBX) only while no other
        conversion of the same uploader holds a live claim. Conversions have few slots, and
        a file can hang Blender for minutes (MOTIONLIB_BLENDER_TIMEOUT): one person's files
        take at most one slot, so they never hold back anybody else's. A conversion refused
        here stays queued; it is sent again when the uploader's conversion ends
        (``Capture.next_in_line``), or by the sweep."""
        busy = self.model.objects.filter(
            CONVERTING, uploaded_by=models.OuterRef("uploaded_by"), status="processing",
            claimed_at__gte=claim_cutoff(),
        ).exclude(pk=models.OuterRef("pk"))
        one_per_person = ~CONVERTING | models.Q(~models.Exists(busy))
        return super(CaptureQuerySet, self.filter(one_per_person)).claim(pk, token)

    def visible_to(self, user):
        """Captures of the projects the user is a member of."""
        return self.filter(project__in=Project.objects.for_user(user))


# A capture whose job is a conversion: an FBX Blender has not read yet.
CONVERTING = models.Q(format="fbx", converted="")


def original_path(capture, filename):
    return f"captures/{capture.project_id}/{uuid.uuid4().hex}/{filename}"


def derived_path(instance, filename):
    return f"derived/{uuid.uuid4().hex}/{filename}"


class Capture(Job):
    """One uploaded take.

    ``original`` (and ``asf`` for AMC) are stored as uploaded and never rewritten, so a
    failed ingest can always be retried or inspected. The metadata fields are empty until
    ingest succeeds; ``positions`` is a float32 ``.npy`` of shape (n_frames, n_joints, 3)
    for playback, in the capture's own length unit, Y up.
    """

    project = models.ForeignKey(Project, models.CASCADE, related_name="captures")
    uploaded_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, related_name="+"
    )
    name = models.CharField(max_length=255)
    original = models.FileField(upload_to=original_path, max_length=500)
    asf = models.FileField(upload_to=original_path, max_length=500, blank=True)
    checksum = models.CharField(max_length=64)
    format = models.CharField(max_length=10)
    fps = models.FloatField(null=True, blank=True)
    n_frames = models.PositiveIntegerField(null=True, blank=True)
    n_joints = models.PositiveIntegerField(null=True, blank=True)
    rest_pose_frame = models.IntegerField(null=True, blank=True)
    skeleton = models.JSONField(null=True, blank=True)
    positions = models.FileField(upload_to=derived_path, max_length=500, blank=True)
    # Bytes of the original (and its ASF) as uploaded, for the storage quotas.
    stored_bytes = models.PositiveBigIntegerField(default=0)
    # Uploaded through the API, where uploads per hour are limited: each further
    # animation of its FBX file is counted against that limit too when it is converted.
    rate_limited = models.BooleanField(default=False)
    created_at = models.DateTimeField(default=timezone.now)
    # FBX: the take Blender read (a saved .npz), written by the convert worker; ingest reads
    # it instead of the original. A file with several animations gives one capture each, all
    # sharing the first one's stored original (``source``), named ``file.fbx#animation``.
    converted = models.FileField(upload_to=derived_path, max_length=500, blank=True)
    animation = models.CharField(max_length=255, blank=True)
    source = models.ForeignKey(
        "self", models.SET_NULL, null=True, blank=True, related_name="animations"
    )
    objects = CaptureQuerySet.as_manager()

    class Meta:
        ordering = ["-created_at", "-id"]
        constraints = [
            models.UniqueConstraint(fields=["project", "checksum"], name="unique_capture_checksum")
        ]
        # The capture list's order: a page is read from the index instead of sorting
        # every visible capture.
        indexes = [models.Index(fields=["-created_at", "-id"], name="capture_newest_first")]

    def __str__(self):
        return self.name

    @property
    def retryable(self):
        """Whether reading the stored original again may succeed: a failure not the file's."""
        return self.status == "failed" and not self.error_permanent

    @property
    def duration(self):
        """Length in seconds, or None before ingest."""
        if self.fps and self.n_frames is not None:
            return self.n_frames / self.fps
        return None

    @property
    def needs_conversion(self):
        """An FBX not yet read by Blender: its next job is ``convert``, not ``ingest``."""
        return self.format == "fbx" and not self.converted

    def check_cut_frame(self, frame, field="frame", cut=None):
        """``frame`` as a cut of this take: an integer strictly inside it (a cut at 0 or at
        ``n_frames`` splits off nothing). ``Invalid`` names ``field`` and the value, and
        ``cut`` when it is one of a list ("cuts: cut 2 at frame 0 is outside 1..399")."""
        if isinstance(frame, bool) or not isinstance(frame, int):
            raise Invalid(f"{field}: must be an integer, got {frame!r}")
        if not 0 < frame < self.n_frames:
            if cut is None:
                raise Invalid(f"{field}: must be between 1 and {self.n_frames - 1}, got {frame}")
            raise Invalid(f"{field}: {cut} at frame {frame} is outside 1..{self.n_frames - 1}")
        return frame

    def first_job(self):
        """The task that starts processing an upload: ``convert`` for an FBX Blender has not
        read yet (the convert queue), else ``ingest``."""
        return "convert" if self.needs_conversion else "ingest"

    def next_in_line(self):
        """The uploader's oldest queued conversion, sent once this conversion ends (it
        waited for this one: ``CaptureQuerySet.claim``); None for other jobs. Asked of any
        FBX capture's job (a conversion that succeeded has its ``converted`` file by now);
        sending one that still cannot start costs nothing: its claim is refused again."""
        if self.format != "fbx" or self.uploaded_by_id is None:
            return None
        return (Capture.objects.filter(CONVERTING, uploaded_by_id=self.uploaded_by_id,
                                       status="queued")
                .exclude(pk=self.pk).order_by("created_at", "pk").first())

    def latest_run(self):
        """The newest detection run (uses ``prefetch_related("runs")`` when present)."""
        return max(self.runs.all(), key=lambda run: (run.created_at, run.id), default=None)

    def latest_finished_run(self):
        """The newest run that finished; reviews start from its candidates."""
        return self.runs.filter(status="ready").order_by("-created_at", "-id").first()


class DetectionRun(Job):
    """One segmenter applied to a capture with validated parameters.

    ``candidates`` is a list of ``{"frame": int, "confidence": float}`` sorted by frame;
    ``signals`` is an ``.npz`` of the feature curves (n_frames,) for display.
    """

    capture = models.ForeignKey(Capture, models.CASCADE, related_name="runs")
    method = models.CharField(max_length=100)
    params = models.JSONField(default=dict)
    candidates = models.JSONField(default=list, blank=True)
    timings = models.JSONField(default=dict, blank=True)
    signals = models.FileField(upload_to=derived_path, max_length=500, blank=True)
    created_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, blank=True, related_name="+"
    )
    created_at = models.DateTimeField(default=timezone.now)
    finished_at = models.DateTimeField(null=True, blank=True)
    # The project model a ``default`` run detected with (see ProjectCutModel); null for
    # the zero-shot detector and for other methods.
    model_version = models.PositiveIntegerField(null=True, blank=True)
    model_n_takes = models.PositiveIntegerField(null=True, blank=True)
    # The label that model's frame model proposes for each segment between the
    # candidates, in frame order: ``{"label": label id or None, "probability": float}``
    # (``len(candidates) + 1`` entries; [] without a frame model).
    proposals = models.JSONField(default=list, blank=True)

    objects = ClaimQuerySet.as_manager()
    task = "detect"

    class Meta:
        ordering = ["-created_at", "-id"]

    def __str__(self):
        return f"{self.method} on {self.capture}"


# Assignments: which annotator is asked to review which capture.
#
# An assignment is a request, not a permission on the review itself: unassigning someone
# leaves their review (their work) in place. Whether annotators may also review captures
# nobody assigned to them is the project's ``annotators_pick_unassigned`` setting.
class Assignment(models.Model):
    capture = models.ForeignKey(Capture, models.CASCADE, related_name="assignments")
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

