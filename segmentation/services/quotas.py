"""Limits that keep one user or project from slowing the service for everyone: upload
rate, stored bytes, detection runs at once. All in settings (``CUTROOM_*``); a refusal
names the limit, the setting and when to try again."""

from django.conf import settings
from django.db.models import Sum
from django.utils import timezone

from segmentation.errors import QuotaExceeded, TooManyRequests
from segmentation.models import Capture, DetectionRun, Project

MB = 1024 * 1024


def check_upload_rate(user):
    """TooManyRequests once ``user`` uploaded CUTROOM_UPLOADS_PER_HOUR captures in the
    last hour (every project counts)."""
    limit = settings.CUTROOM_UPLOADS_PER_HOUR
    since = timezone.now() - timezone.timedelta(hours=1)
    recent = Capture.objects.filter(uploaded_by=user, created_at__gte=since)
    if limit and recent.count() >= limit:
        oldest = recent.order_by("created_at").values_list("created_at", flat=True).first()
        wait = max(1, int((oldest - since).total_seconds()) + 1)
        raise TooManyRequests(
            f"file: you uploaded {limit} captures in the last hour; the limit is {limit} "
            f"per hour (CUTROOM_UPLOADS_PER_HOUR); try again in {wait} s",
            retry_after=wait,
        )


def check_storage(project, user, size):
    """QuotaExceeded if storing ``size`` more bytes would take ``project`` past
    CUTROOM_PROJECT_STORAGE_MB or ``user`` past CUTROOM_USER_STORAGE_MB."""
    for owner, used, limit, setting in (
        (f"project {project.name!r}", _stored(project=project),
         settings.CUTROOM_PROJECT_STORAGE_MB, "CUTROOM_PROJECT_STORAGE_MB"),
        ("your uploads", _stored(uploaded_by=user),
         settings.CUTROOM_USER_STORAGE_MB, "CUTROOM_USER_STORAGE_MB"),
    ):
        if limit and used + size > limit * MB:
            raise QuotaExceeded(
                f"file: {owner} already store {used / MB:.1f} MB; this upload "
                f"({size / MB:.1f} MB) would pass the quota of {limit} MB ({setting}). "
                "Delete captures or ask the administrators to raise it."
            )


def _stored(**owner):
    return Capture.objects.filter(**owner).aggregate(total=Sum("stored_bytes"))["total"] or 0


def check_active_runs(project):
    """TooManyRequests while ``project`` has CUTROOM_PROJECT_ACTIVE_RUNS detection runs
    queued or running.

    Call it in the transaction that creates the run: it locks the project row until that
    transaction ends, so starts at the same moment count one after the other and never
    both pass the last free place (on SQLite the IMMEDIATE transaction serialises them).
    """
    Project.objects.select_for_update().filter(pk=project.pk).first()
    limit = settings.CUTROOM_PROJECT_ACTIVE_RUNS
    active = DetectionRun.objects.filter(
        capture__project=project, status__in=("queued", "processing")
    ).count()
    if limit and active >= limit:
        raise TooManyRequests(
            f"method: project {project.name!r} has {active} detection runs queued or "
            f"running; the limit is {limit} at once (CUTROOM_PROJECT_ACTIVE_RUNS); start "
            "this one when one of them has finished",
            retry_after=30,
        )
