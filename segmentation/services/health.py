"""Is the service working? Asked from outside the workers: by a watcher (``make up``'s
supervisor, ``manage.py watch_jobs`` in compose's watchdog) every few seconds, so a worker
that hangs cannot hide it and the jobs of a dead or hung worker are requeued without it;
and by monitoring, through ``GET /api/health/`` (:func:`report`).

Workers say they are alive by a heartbeat row their main process writes (:func:`beat`)."""

import logging
import threading
import time

from django.conf import settings
from django.db import connection
from django.db.models import Max, Min, Q
from django.db.models.functions import Coalesce
from django.utils import timezone

from segmentation import workers
from segmentation.models import Capture, DetectionRun, LibrarySegment, WorkerHeartbeat
from segmentation.models.captures import CONVERTING
from segmentation.models.jobs import claim_cutoff
from segmentation.services import jobs
from segmentation.similar import files

log = logging.getLogger(__name__)

JOBS = (Capture, DetectionRun)


def look(concurrency):
    """One look by the watcher, every CUTROOM_SWEEP_SECONDS: requeue the jobs of processes
    that died (failing those started too often), resend jobs whose message was lost, then
    ask whether the workers are stuck.

    Returns (jobs requeued, failed or resent; why the workers look stuck, or None).
    """
    swept = jobs.sweep()
    return swept, stalled(concurrency)


def resend_stalled():
    """Send again the queued jobs that waited CUTROOM_STALL_SECONDS (how many): what looks
    like a stuck worker is as often a lost message (a broker restarted, a queue purged),
    which a healthy worker takes at once when it is sent again, and restarting the worker
    would not bring back."""
    return jobs.resend_waiting(settings.CUTROOM_STALL_SECONDS)


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
    oldest = _earliest(watched(model).filter(status="queued") for model in JOBS)
    if oldest is None or oldest > limit:
        return None
    taken = _latest(watched(model).exclude(status="queued") for model in JOBS)
    if taken is not None and taken > limit:
        return None
    running = sum(
        watched(model).filter(status="processing", claimed_at__gte=claim_cutoff()).count()
        for model in JOBS
    )
    if running >= concurrency:
        return None
    return (
        f"a job has waited {(now - oldest).total_seconds():.0f} s in the queue and no job "
        f"was taken for {after} s (CUTROOM_STALL_SECONDS) while {running} of "
        f"{concurrency} worker processes had one"
    )


def watched(model):
    """The jobs of ``model`` the default queue's workers run: not FBX conversions, which the
    convert worker runs (and which wait on purpose while their uploader has one running)."""
    return model.objects.exclude(CONVERTING) if model is Capture else model.objects.all()


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


def beat(hostname, queues, processes):
    """Record a worker's heartbeat now, and then every CUTROOM_HEARTBEAT_SECONDS from a
    thread of its main process (which a busy pool process never holds up)."""

    def record():
        now = timezone.now()
        try:
            heartbeat, made = WorkerHeartbeat.objects.get_or_create(
                hostname=hostname, defaults={"queues": queues, "processes": processes,
                                             "started_at": now, "seen_at": now})
            if not made:
                WorkerHeartbeat.objects.filter(pk=heartbeat.pk).update(
                    queues=queues, processes=processes, seen_at=now)
        except Exception:  # the database away for a moment: the next beat tries again
            log.exception("could not record the heartbeat of worker %s", hostname)
        finally:
            connection.close()

    def forever():
        while True:
            record()
            time.sleep(settings.CUTROOM_HEARTBEAT_SECONDS)

    threading.Thread(target=forever, name=f"heartbeat {hostname}", daemon=True).start()


def report():
    """The service's health for monitoring: (ok, checks), each check a dict with ``ok``
    and what it found. Checks: the database, the broker, the workers of the default queue
    (heard of lately, and not stuck), the convert worker, the similar-clip indexes."""
    checks = {}
    for name, check in (("database", _database), ("broker", _broker),
                        ("workers", _workers), ("convert_worker", _convert_worker),
                        ("similar_index", _similar_index)):
        try:
            checks[name] = check()
        except Exception as exc:
            checks[name] = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
    return all(c["ok"] for c in checks.values()), checks


def _database():
    with connection.cursor() as cursor:
        cursor.execute("SELECT 1")
    return {"ok": True, "vendor": connection.vendor}


def _broker():
    return {"ok": True, "transport": workers.ping_broker()}


def _alive(queue):
    since = timezone.now() - timezone.timedelta(seconds=settings.CUTROOM_HEARTBEAT_STALE)
    return [h for h in WorkerHeartbeat.objects.filter(seen_at__gte=since) if queue in h.queues]


def _workers():
    queue = settings.CELERY_TASK_DEFAULT_QUEUE
    alive = _alive(queue)
    processes = sum(h.processes for h in alive)
    found = {"workers": len(alive), "processes": processes}
    if not alive:
        return {"ok": False, **found, "error": f"no worker of the queue {queue!r} was heard of "
                f"in the last {settings.CUTROOM_HEARTBEAT_STALE} s (CUTROOM_HEARTBEAT_STALE)"}
    stuck = stalled(processes)
    return {"ok": stuck is None, **found, **({"error": stuck} if stuck else {})}


def _convert_worker():
    queue = settings.CUTROOM_CONVERT_QUEUE
    alive = _alive(queue)
    converting = Capture.objects.filter(CONVERTING, status="processing").count()
    found = {"workers": len(alive), "slots": sum(h.processes for h in alive),
             "converting": converting}
    if not alive:
        return {"ok": False, **found, "error": f"no worker of the convert queue {queue!r} was "
                f"heard of in the last {settings.CUTROOM_HEARTBEAT_STALE} s: FBX uploads wait"}
    return {"ok": True, **found}


def _similar_index():
    """Stale: a project's library segment waited more than CUTROOM_INDEX_STALE_SECONDS to
    enter its index (no index, an unusable one, or one that stopped being updated)."""
    limit = timezone.now() - timezone.timedelta(seconds=settings.CUTROOM_INDEX_STALE_SECONDS)
    projects = (LibrarySegment.objects.filter(profile__isnull=False)
                .order_by("project_id").values_list("project_id", flat=True).distinct())
    stale = []
    for project_id in projects:
        try:
            indexed_up_to = files.read_manifest(project_id)["max_id"]
        except files.IndexUnusable:
            indexed_up_to = 0
        waiting = (files.described(project_id).filter(id__gt=indexed_up_to)
                   .aggregate(t=Min("created_at"))["t"])
        if waiting is not None and waiting < limit:
            stale.append(project_id)
    found = {"projects": len(projects), "stale": stale}
    if stale:
        return {"ok": False, **found, "error": f"the similar-clip index of project(s) "
                f"{', '.join(map(str, stale))} lacks segments older than "
                f"{settings.CUTROOM_INDEX_STALE_SECONDS} s (CUTROOM_INDEX_STALE_SECONDS)"}
    return {"ok": True, **found}
