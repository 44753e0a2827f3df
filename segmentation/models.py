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
    # Whether annotators may start reviewing captures nobody assigned to them.
    annotators_pick_unassigned = models.BooleanField(default=True)
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
    # The taxonomy's order in the app; a retired label stays on existing segments but
    # is no longer offered for new ones.
    position = models.PositiveIntegerField(default=0)
    retired = models.BooleanField(default=False)

    class Meta:
        ordering = ["position", "id"]
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
    def duration(self):
        """Length in seconds, or None before ingest."""
        if self.fps and self.n_frames is not None:
            return self.n_frames / self.fps
        return None

    @property
    def needs_conversion(self):
        """An FBX not yet read by Blender: its next job is ``convert``, not ``ingest``."""
        return self.format == "fbx" and not self.converted

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
    return_comment = models.TextField(blank=True)
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

    def segments(self):
        """Intervals between kept cuts: list of (index, start, stop, label name or None).

        A segment's label is stored against the cut that starts it (no cut for the
        first segment), so labels follow their cut when it is moved.
        """
        kept = self.kept_frames()
        labels = dict(self.segment_labels.filter(label__isnull=False).values_list("cut_id", "label__name"))
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


class CutModelQuerySet(ClaimQuerySet):
    def claim(self, pk, token):
        """Claim a training unless another training of the same project holds a live
        claim: one training at a time per project. Zero rows updated means it is not
        this job's turn (or another worker has it)."""
        stale = timezone.now() - timezone.timedelta(seconds=settings.CUTROOM_CLAIM_TIMEOUT)
        busy = self.model.objects.filter(
            project=models.OuterRef("project"), status="processing", claimed_at__gte=stale
        ).exclude(pk=models.OuterRef("pk"))
        return super(CutModelQuerySet, self.filter(~models.Exists(busy))).claim(pk, token)

    def newest(self, project_id):
        """The project's newest trained model, or None (zero-shot)."""
        return self.filter(project_id=project_id, status="ready").order_by("-version").first()


class ProjectCutModel(Job):
    """One training of a project's cut model from its reviewed takes.

    A row is one request: queued when a review is submitted or a gold version saved
    (later requests fold into the queued one), then trained by a worker. A trained row
    gets the project's next ``version``; a failed one keeps its ``error`` and no version,
    and detection goes on with the newest trained version. ``model`` is
    ``motionlib.adapt.CutModel.to_json()``.
    """

    project = models.ForeignKey(Project, models.CASCADE, related_name="cut_models")
    version = models.PositiveIntegerField(null=True, blank=True)
    model = models.TextField(blank=True)
    n_takes = models.PositiveIntegerField(default=0)
    n_cuts = models.PositiveIntegerField(default=0)
    seconds = models.FloatField(null=True, blank=True)
    created_at = models.DateTimeField(default=timezone.now)
    finished_at = models.DateTimeField(null=True, blank=True)

    objects = CutModelQuerySet.as_manager()

    class Meta:
        ordering = ["-created_at", "-id"]
        constraints = [
            models.UniqueConstraint(fields=["project", "version"], name="one_cut_model_per_version"),
            # Requests made while one is waiting join it: one queued training per project.
            models.UniqueConstraint(
                fields=["project"], condition=Q(status="queued"), name="one_queued_training"
            ),
        ]

    def __str__(self):
        return f"cut model v{self.version} of {self.project}" if self.version else (
            f"training of {self.project} ({self.status})")


# The clip library and agreement records, and invitations, live in their own modules
# (same app, same migrations); importing them here registers them with the app.
from segmentation.models_assignments import Assignment  # noqa: E402, F401
from segmentation.models_invitations import Invitation  # noqa: E402, F401
from segmentation.models_library import (  # noqa: E402, F401
    Adjudication,
    CaptureAgreement,
    LibrarySegment,
)
from segmentation.models_suggestions import LabelSuggestion, SuggestionRequest  # noqa: E402, F401
