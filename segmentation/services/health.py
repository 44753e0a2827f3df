"""Is background work making progress? Asked by a watcher outside the workers (``make
up``'s supervisor, ``manage.py watch_jobs`` in compose's watchdog), so a worker that hangs
cannot hide it, and the jobs of a dead or hung worker are requeued without it."""

from django.conf import settings
from django.db.models import Max, Min, Q
from django.db.models.functions import Coalesce
from django.utils import timezone

from segmentation.models import Capture, DetectionRun
from segmentation.models.jobs import claim_cutoff
from segmentation.services import jobs

JOBS = (Capture, DetectionRun)


def look(concurrency):
    """One look by the watcher, every CUTROOM_SWEEP_SECONDS: requeue the jobs of processes
    that died (failing those started too often), resend jobs whose message was lost, then
    ask whether the workers are stuck.

    Returns (jobs requeued, failed or resent; why the workers look stuck, or None).
    """
    swept = jobs.sweep()
    return swept, stalled(concurrency)


def stalled(concurrency, after=None):
    """Why the workers look stuck, or None while they make progress.

    Stuck means: a job has waited in the queue for more than ``after`` seconds
    (CUTROOM_STALL_SECONDS), no job was taken in that time, and fewer than
    ``concurrency`` jobs are running, so a free worker process is not taking work (a
    hung pool, a lost message). Busy workers on long jobs are not stuck.
    """
    after = settings.CUTROOM_STALL_SECONDS if after is None else after
    now = timezone.now()
    limit = now - timezone.timedelta(seconds=after)
    oldest = _earliest(model.objects.filter(status="queued") for model in JOBS)
    if oldest is None or oldest > limit:
        return None
    taken = _latest(model.objects.exclude(status="queued") for model in JOBS)
    if taken is not None and taken > limit:
        return None
    running = sum(
        model.objects.filter(status="processing", claimed_at__gte=claim_cutoff()).count()
        for model in JOBS
    )
    if running >= concurrency:
        return None
    return (
        f"a job has waited {(now - oldest).total_seconds():.0f} s in the queue and no job "
        f"was taken for {after} s (CUTROOM_STALL_SECONDS) while {running} of "
        f"{concurrency} worker processes had one"
    )


def _earliest(querysets):
    """When the longest-waiting queued job was sent (created, or last requeued)."""
    times = [
        qs.aggregate(t=Min(Coalesce("claimed_at", "created_at")))["t"] for qs in querysets
    ]
    return min((t for t in times if t is not None), default=None)


def _latest(querysets):
    times = [qs.aggregate(t=Max("claimed_at", filter=Q(claimed_at__isnull=False)))["t"]
             for qs in querysets]
    return max((t for t in times if t is not None), default=None)
