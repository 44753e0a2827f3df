"""Cutroom's records: projects, captures, detection runs, reviews and their audit log.

Rules about one record live here; lookups live on the managers
(``Capture.objects.visible_to(user)``). Workflows that touch several records are the
``do_*`` functions in ``segmentation.services``.
"""

import uuid

from django.conf import settings
from django.db import models
from django.db.models import F, Q
from django.utils import timezone

ROLES = (("annotator", "Annotator"), ("reviewer", "Reviewer"), ("admin", "Admin"))
JOB_STATUSES = (
    ("queued", "Queued"),
    ("processing", "Processing"),
    ("ready", "Ready"),
    ("failed", "Failed"),
)


class ProjectQuerySet(models.QuerySet):
    def for_user(self, user):
        """Projects the user is a member of (any role)."""
        if not user.is_authenticated:
            return self.none()
        return self.filter(memberships__user=user)


class Project(models.Model):
    """A studio's library: members, label taxonomy, default segmentation method.

    An empty ``default_method`` means "the registry's recommended method", resolved at
    detection time (see ``services.default_method``).
    """

    name = models.CharField(max_length=200)
    default_method = models.CharField(max_length=100, blank=True)
    default_params = models.JSONField(default=dict, blank=True)
    created_at = models.DateTimeField(default=timezone.now)

    objects = ProjectQuerySet.as_manager()

    def __str__(self):
        return self.name

    def role_of(self, user):
        """The user's role in this project, or None for a non-member."""
        if not user.is_authenticated:
            return None
        member = self.memberships.filter(user=user).first()
        return member.role if member else None

    def can_manage(self, user):
        return self.role_of(user) == "admin"

    def can_see_all_reviews(self, user):
        return self.role_of(user) in ("reviewer", "admin")


class Membership(models.Model):
    project = models.ForeignKey(Project, models.CASCADE, related_name="memberships")
    user = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="memberships")
    role = models.CharField(max_length=20, choices=ROLES, default="annotator")

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["project", "user"], name="one_membership_per_user")
        ]

    def __str__(self):
        return f"{self.user} in {self.project} ({self.role})"


class Label(models.Model):
    """One entry of a project's label taxonomy (walk, punch…)."""

    project = models.ForeignKey(Project, models.CASCADE, related_name="labels")
    name = models.CharField(max_length=100)
    color = models.CharField(max_length=7, default="#888888")
    # NULL, not "", means "no hotkey" so that only real hotkeys must be unique.
    hotkey = models.CharField(max_length=1, null=True, blank=True)  # noqa: DJ001

    class Meta:
        ordering = ["id"]
        constraints = [
            models.UniqueConstraint(fields=["project", "name"], name="unique_label_name"),
            models.UniqueConstraint(
                fields=["project", "hotkey"],
                condition=Q(hotkey__isnull=False),
                name="unique_label_hotkey",
            ),
        ]

    def __str__(self):
        return self.name


class ClaimQuerySet(models.QuerySet):
    """Claiming background work with one conditional UPDATE.

    A row can be claimed when it is queued, when the same job message comes back after
    its worker died (same ``claim_token``), or when another claim is older than
    ``CUTROOM_CLAIM_TIMEOUT``. Zero rows updated means another worker has the job.
    """

    def claim(self, pk, token):
        stale = timezone.now() - timezone.timedelta(seconds=settings.CUTROOM_CLAIM_TIMEOUT)
        claimable = Q(status="queued") | Q(status="processing") & (
            Q(claim_token=token) | Q(claimed_at__lt=stale)
        )
        updated = self.filter(claimable, pk=pk).update(
            status="processing",
            claim_token=token,
            claimed_at=timezone.now(),
            attempts=F("attempts") + 1,
        )
        return updated == 1

    def stale(self):
        """Rows still marked processing whose claim was not renewed within the claim
        timeout: the process running them died."""
        limit = timezone.now() - timezone.timedelta(seconds=settings.CUTROOM_CLAIM_TIMEOUT)
        return self.filter(status="processing", claimed_at__lt=limit)

    def requeue_failed(self, pk):
        """Put a failed job back in the queue with a fresh attempt count; 0 rows updated
        means it was not failed (a concurrent retry, or nothing to retry)."""
        return self.filter(pk=pk, status="failed").update(
            status="queued", error="", claim_token="", claimed_at=timezone.now(), attempts=0
        ) == 1

    def waiting_too_long(self):
        """Queued rows nobody claimed within CUTROOM_RESEND_AFTER: their message may be
        lost (broker down at upload time, queue purged), so they are sent again."""
        limit = timezone.now() - timezone.timedelta(seconds=settings.CUTROOM_RESEND_AFTER)
        last_sent = Q(claimed_at__lt=limit) | Q(claimed_at__isnull=True, created_at__lt=limit)
        return self.filter(last_sent, status="queued")


class JSONArrayLength(models.Func):
    """Length of a JSON array column, counted by the database (SQLite and PostgreSQL)."""

    function = "JSON_ARRAY_LENGTH"
    output_field = models.IntegerField()

    def as_postgresql(self, compiler, connection, **extra):
        return self.as_sql(compiler, connection, function="JSONB_ARRAY_LENGTH", **extra)


class Job(models.Model):
    """State shared by the two kinds of background work (ingest, detect)."""

    status = models.CharField(max_length=20, choices=JOB_STATUSES, default="queued")
    error = models.TextField(blank=True)
    claim_token = models.CharField(max_length=64, blank=True)
    # Time of the last claim, or of the last requeue while queued.
    claimed_at = models.DateTimeField(null=True, blank=True)
    attempts = models.PositiveIntegerField(default=0)

    class Meta:
        abstract = True

    def finish(self, **fields):
        """Store the result, but only if this job's claim still holds."""
        return self._close("ready", "", fields)

    def fail(self, error, **fields):
        return self._close("failed", error, fields)

    def _close(self, status, error, fields):
        fields.update(status=status, error=error)
        updated = (
            type(self)
            .objects.filter(pk=self.pk, status="processing", claim_token=self.claim_token)
            .update(**fields)
        )
        if updated:
            for name, value in fields.items():
                setattr(self, name, value)
        return updated == 1


class CaptureQuerySet(ClaimQuerySet):
    def visible_to(self, user):
        """Captures of the projects the user is a member of."""
        return self.filter(project__in=Project.objects.for_user(user))


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
    created_at = models.DateTimeField(default=timezone.now)

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
    def duration(self):
        """Length in seconds, or None before ingest."""
        if self.fps and self.n_frames is not None:
            return self.n_frames / self.fps
        return None

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

    objects = ClaimQuerySet.as_manager()

    class Meta:
        ordering = ["-created_at", "-id"]

    def __str__(self):
        return f"{self.method} on {self.capture}"


class Review(models.Model):
    """One annotator's work on one capture, started from a run's candidates.

    Every write is conditional on ``version`` (see ``services``): a write based on a stale
    version is refused instead of merged.
    """

    STATUSES = (("in_progress", "In progress"), ("submitted", "Submitted"))

    capture = models.ForeignKey(Capture, models.CASCADE, related_name="reviews")
    annotator = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="reviews")
    run = models.ForeignKey(DetectionRun, models.SET_NULL, null=True, blank=True)
    status = models.CharField(max_length=20, choices=STATUSES, default="in_progress")
    version = models.PositiveIntegerField(default=1)
    created_at = models.DateTimeField(default=timezone.now)
    updated_at = models.DateTimeField(default=timezone.now)
    submitted_at = models.DateTimeField(null=True, blank=True)

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

    def segments(self):
        """Intervals between kept cuts: list of (index, start, stop, label name or None).

        A segment's label is stored against the cut that starts it (no cut for the
        first segment), so labels follow their cut when it is moved.
        """
        kept = sorted(self.kept_cuts(), key=lambda c: c.frame)
        rows = self.segment_labels.select_related("label")
        labels = {s.cut_id: s.label.name for s in rows if s.label_id}
        starts = [(None, 0)] + [(c.id, c.frame) for c in kept]
        stops = [c.frame for c in kept] + [self.capture.n_frames or 0]
        return [
            (index, start, stop, labels.get(cut_id))
            for index, ((cut_id, start), stop) in enumerate(zip(starts, stops, strict=True))
        ]

    def segment_start_cut(self, index):
        """The cut that starts segment ``index`` (None for the first); IndexError if none."""
        kept = sorted(self.kept_cuts(), key=lambda c: c.frame)
        if index < 0 or index > len(kept):
            raise IndexError(index)
        return kept[index - 1] if index else None


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


# The clip library and agreement records live in their own module (same app, same
# migrations); importing them here registers them with the app.
from segmentation.models_library import (  # noqa: E402, F401
    Adjudication,
    CaptureAgreement,
    LibrarySegment,
)
