"""Limits that keep one user or project from slowing the service for everyone: upload
rate, stored bytes, detection runs at once. All in settings (``CUTROOM_*``); a refusal
names the limit, the setting and when to try again.

Each check counts under row locks taken by ``lock`` (the project's row, then one for the
user, in that order everywhere so two transactions never wait on each other in a cycle), and
must run in the transaction that then inserts what it counted: requests at the same
moment are counted one after the other, so none passes a limit another has just reached.
On SQLite the service's IMMEDIATE transactions run one at a time anyway.
"""

from django.conf import settings
from django.db.models import Sum
from django.utils import timezone

from accounts import locks
from segmentation.errors import Invalid, QuotaExceeded, TooManyRequests
from segmentation.models import Capture, DetectionRun, Project, ReferenceVideo

MB = 1024 * 1024
ACTIVE = ("queued", "processing")


def lock(project=None, user=None):
    """Lock the project's row, then the user's lock row, until the transaction ends.

    The user's is a ``ThrottleLock`` row rather than the account's own, so that counting
    never holds up a sign-in (which writes ``last_login``) or an edit in the admin.
    """
    if project is not None:
        Project.objects.select_for_update().filter(pk=project.pk).first()
    if user is not None and user.pk is not None:
        locks.hold([f"quotas:user:{user.pk}"])


def check_upload_rate(user, uploads=1, fbx=None):
    """TooManyRequests unless ``user`` may add ``uploads`` captures to those made in the
    last hour (every project counts, and every animation of a multi-animation FBX), with
    CUTROOM_UPLOADS_PER_HOUR at most. For the animations of the FBX capture ``fbx``, that
    capture and the animations it already gave are not counted again. Call it under
    ``lock(user=...)``."""
    limit = settings.CUTROOM_UPLOADS_PER_HOUR
    if not limit:
        return
    since = timezone.now() - timezone.timedelta(hours=1)
    recent = Capture.objects.filter(uploaded_by=user, created_at__gte=since)
    if fbx is not None:
        recent = recent.exclude(pk=fbx.pk).exclude(source=fbx)
    made = recent.count()
    if made + uploads <= limit:
        return
    if uploads > limit:
        raise Invalid(
            f"file: this file holds {uploads} animations, each counted as an upload, and the "
            f"limit is {limit} uploads per hour (CUTROOM_UPLOADS_PER_HOUR), so it can never "
            f"pass, however long you wait; split it into files of at most {limit} animations, "
            "or ask the administrators to raise the limit"
        )
    # The wait until enough of the last hour's uploads are an hour old to make room.
    to_age = made + uploads - limit
    times = recent.order_by("created_at").values_list("created_at", flat=True)
    freed = times[to_age - 1] if to_age <= made else None
    wait = max(1, int((freed - since).total_seconds()) + 1) if freed else 3600
    if uploads == 1:
        what = ""
    else:
        what = f"this file holds {uploads} animations, each counted as an upload; "
    raise TooManyRequests(
        f"file: {what}you uploaded {made} captures in the last hour; the limit is {limit} "
        f"per hour (CUTROOM_UPLOADS_PER_HOUR); try again in {wait} s",
        retry_after=wait,
    )


def check_storage(project, user, size):
    """QuotaExceeded if storing ``size`` more bytes would take ``project`` past
    CUTROOM_PROJECT_STORAGE_MB or ``user`` past CUTROOM_USER_STORAGE_MB. Captures and
    their reference videos both count."""
    for owner, used, limit, setting in (
        (f"project {project.name!r}",
         _stored(Capture, project=project) + _stored(ReferenceVideo, capture__project=project),
         settings.CUTROOM_PROJECT_STORAGE_MB, "CUTROOM_PROJECT_STORAGE_MB"),
        ("your uploads", _stored(Capture, uploaded_by=user) + _stored(ReferenceVideo, uploaded_by=user),
         settings.CUTROOM_USER_STORAGE_MB, "CUTROOM_USER_STORAGE_MB"),
    ):
        if limit and used + size > limit * MB:
            raise QuotaExceeded(
                f"file: {owner} already store {used / MB:.1f} MB; this upload "
                f"({size / MB:.1f} MB) would pass the quota of {limit} MB ({setting}). "
                "Delete captures or ask the administrators to raise it."
            )


def _stored(model, **owner):
    return model.objects.filter(**owner).aggregate(total=Sum("stored_bytes"))["total"] or 0


def check_active_runs(project, user=None):
    """TooManyRequests while ``project`` has CUTROOM_PROJECT_ACTIVE_RUNS detection runs
    queued or running, or ``user`` has started CUTROOM_USER_ACTIVE_RUNS of them in any
    of their projects (projects cost nothing to create, so a per-project limit alone
    bounds nobody).

    Takes the locks itself; call it in the transaction that creates the run.
    """
    lock(project, user)
    limit = settings.CUTROOM_PROJECT_ACTIVE_RUNS
    active = DetectionRun.objects.filter(capture__project=project, status__in=ACTIVE).count()
    if limit and active >= limit:
        raise TooManyRequests(
            f"method: project {project.name!r} has {active} detection runs queued or "
            f"running; the limit is {limit} at once (CUTROOM_PROJECT_ACTIVE_RUNS); start "
            "this one when one of them has finished",
            retry_after=30,
        )
    limit = settings.CUTROOM_USER_ACTIVE_RUNS
    if not limit or user is None or user.pk is None:
        return
    mine = DetectionRun.objects.filter(created_by=user, status__in=ACTIVE).count()
    if mine >= limit:
        raise TooManyRequests(
            f"method: you have {mine} detection runs queued or running across your "
            f"projects; the limit is {limit} at once per person (CUTROOM_USER_ACTIVE_RUNS); "
            "start this one when one of them has finished",
            retry_after=30,
        )
