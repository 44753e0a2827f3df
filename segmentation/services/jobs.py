"""The job runner: one lifecycle for every kind of background work (a capture's ingest or
conversion, a detection run, a cut-model training).

A job is a row (``models.Job``). Its task claims the row with one conditional UPDATE
(0 rows: another worker has it, or it is done), renews the claim while the work runs,
guards the work so that any error closes the row as failed with a text a person can act
on, and closes it with its result. A job that waits behind it (a project's next training)
is sent once it closes. One sweep requeues the jobs whose worker vanished and resends the
queued ones whose message may be lost.

Nothing here imports Celery: jobs are sent by task name through ``segmentation.workers``,
which ``segmentation.tasks`` connects to the broker.
"""

import dataclasses
import logging
import threading
from collections.abc import Callable
from contextlib import contextmanager

from django.conf import settings
from django.db import IntegrityError, connection, transaction
from django.utils import timezone

from motionlib.errors import MotionlibError
from segmentation import workers
from segmentation.errors import CutroomError, internal_error
from segmentation.models import Capture, DetectionRun, ProjectCutModel

log = logging.getLogger(__name__)

# The models whose rows are jobs, in the order the sweep looks at them.
JOB_MODELS = (Capture, DetectionRun, ProjectCutModel)
# Longest error text a job stores from a domain error (a whole file's worth of context
# would not help the person reading it).
MAX_ERROR_CHARS = 2000


@dataclasses.dataclass(frozen=True)
class Kind:
    """One kind of job: the task that runs it, its row's model, how its errors name it
    (``what``: "Ingest"), the work done on a claimed row, the setting of its time limit
    and the setting naming its queue ("": the default queue)."""

    task: str
    model: type
    what: str
    work: Callable
    limit: str
    queue: str = ""


KINDS = {}


def register(kind):
    """Make ``kind`` known by its task name (to send it, sweep it, run it)."""
    KINDS[kind.task] = kind
    return kind


# ---- sending -----------------------------------------------------------------------------


def enqueue(task_name, pk, countdown=0):
    """Send job ``pk`` of kind ``task_name`` once the row is committed (a worker must be
    able to see it), ``countdown`` seconds later, on its kind's queue."""
    options = {"countdown": countdown} if countdown else {}
    queue = KINDS[task_name].queue
    if queue:
        options["queue"] = getattr(settings, queue)
    transaction.on_commit(lambda: workers.send(task_name, pk, **options))


# ---- running -----------------------------------------------------------------------------


def run(kind, pk, token, work=None):
    """Claim job ``pk`` of ``kind`` with ``token`` (the task's id) and do its work under the
    guard; does nothing if another worker has the job or it is done."""
    job = claim(kind.model, pk, token)
    if job is not None:
        guard(kind, job, work)


def claim(model, pk, token):
    """The claimed row, or None if another worker has it, it is not its turn or it is
    already done. A job claimed more than CUTROOM_MAX_ATTEMPTS times (its input keeps
    killing workers) fails instead."""
    if not model.objects.claim(pk, token):
        return None
    job = model.objects.get(pk=pk)
    if job.attempts > settings.CUTROOM_MAX_ATTEMPTS:
        give_up(job)
        return None
    return job


def guard(kind, job, work=None):
    """Do ``work(job)`` (the kind's work by default) on a claimed job while renewing its
    claim; any error fails the job, so a job never stays "processing" because of its input
    or a bug. Then send the job that waited behind this one.

    A domain error (motionlib's, naming file, line and value, or the service's own) is the
    input's fault: its message is stored as it is, as a permanent error (unless the error's
    ``permanent`` is False: Blender killed from outside, which a retry may outlive); so is the soft
    time limit, which the same input would reach again. Anything else is ours: it is
    logged with its traceback and the job stores an internal error with a reference to
    quote.
    """
    model = type(job)
    try:
        with heartbeat(job):
            (work or kind.work)(job)
    except workers.stopped():
        usable_connection()
        job.fail(model.stopped_error.format(what=kind.what, settings=settings), permanent=True)
    except (MotionlibError, CutroomError) as exc:
        # Permanent unless the error says trying again may help (Blender killed from outside).
        job.fail(_bounded(model.input_error.format(error=exc)),
                 permanent=getattr(exc, "permanent", True))
    except Exception:
        if not model.objects.filter(pk=job.pk).exists():
            # Deleted while it ran (its stored files with it): nothing failed that matters.
            log.info("%s of %s %s ended: the row was deleted meanwhile", kind.what,
                     model._meta.verbose_name, job.pk)
            return
        reference = internal_error(f"{kind.what} of {model._meta.verbose_name} {job.pk}", log)
        usable_connection()
        job.fail(model.crashed_error.format(what=kind.what, reference=reference))
    finally:
        send_next(job)


def _bounded(text):
    return text if len(text) <= MAX_ERROR_CHARS else text[:MAX_ERROR_CHARS] + "..."


@contextmanager
def heartbeat(job):
    """Renew ``job``'s claim while the block runs.

    A claim not renewed for CUTROOM_CLAIM_TIMEOUT seconds means its process died (a pool
    process killed, a worker lost with its machine); the sweep then requeues the job. So
    a dead job is noticed within that timeout, however long a live job runs.
    """
    stop = threading.Event()
    interval = max(settings.CUTROOM_CLAIM_TIMEOUT / 6, 0.2)
    owned = type(job).objects.filter(pk=job.pk, status="processing", claim_token=job.claim_token)

    def renew():
        try:
            while not stop.wait(interval):
                owned.update(claimed_at=timezone.now())
        except Exception:
            log.exception("could not renew the claim on %s", job)
        finally:
            connection.close()

    beating = threading.Thread(target=renew, name=f"heartbeat {job}", daemon=True)
    beating.start()
    try:
        yield
    finally:
        stop.set()
        beating.join()


def usable_connection():
    """Close this thread's database connection if it can no longer run a query, so the
    next query opens a new one.

    A task's soft time limit raises its exception from a signal handler, wherever the job
    is: inside a query waiting for its result, too. That connection is then left in the
    middle of a command and every later query on it fails ("another command is already in
    progress"), the one that records why the job failed included.
    """
    if connection.connection is None or connection.in_atomic_block:
        return
    if not connection.is_usable():
        log.warning("closing a database connection left in the middle of a command")
        connection.close()


def send_next(job):
    """Once ``job`` has ended, send the job that waited behind it (its own message may
    have found this one running and been dropped), once the transaction commits."""
    waiting = job.next_in_line()
    if waiting is not None:
        enqueue(waiting.first_job(), waiting.pk)  # on commit, on its kind's queue


# ---- failing jobs that did not end by themselves ---------------------------------------


def give_up(job):
    """Fail a job that was started too often and never finished, saying why; it is not a
    permanent error (the workers may have been lost for reasons of their own)."""
    failed = job.fail(type(job).abandoned_error.format(attempts=job.attempts))
    send_next(job)
    return failed


def fail_at_time_limit(kind, pk, token):
    """Fail job ``pk`` whose process was killed at its hard time limit (it did not stop at
    the soft one), if it still holds the claim ``token``. Returns whether it was failed.

    Unlike a job whose process died for another reason, it is not retried: the same input
    would run as long again.
    """
    job = kind.model.objects.filter(pk=pk, status="processing", claim_token=token).first()
    if job is None:
        return False
    killed = killed_at_time_limit(kind.what, kind.limit)
    failed = job.fail(kind.model.killed_error.format(killed=killed), permanent=True)
    send_next(job)
    return failed


def killed_at_time_limit(what, setting):
    """The first sentence of the error of a job killed at its hard time limit."""
    return (f"{what} stopped after its time limit of {getattr(settings, setting)} s "
            f"({setting}): it did not stop by itself, so its process was killed.")


# ---- the sweep ---------------------------------------------------------------------------


def sweep():
    """Requeue jobs whose worker vanished mid-way (failing those retried too often, and
    those a newer job waits behind) and resend jobs queued for longer than
    CUTROOM_RESEND_AFTER.

    Returns the number of jobs requeued, failed or resent.
    """
    count = 0
    for model in JOB_MODELS:
        count += _resend_waiting(model) + _rescue_stale(model)
    return count


def _rescue_stale(model):
    count = 0
    for job in model.objects.stale():
        if job.attempts >= settings.CUTROOM_MAX_ATTEMPTS or job.queued_behind() is not None:
            count += give_up(job)
            continue
        try:
            with transaction.atomic():
                requeued = model.objects.filter(
                    pk=job.pk, status="processing", claim_token=job.claim_token
                ).update(status="queued", claim_token="", claimed_at=timezone.now())
                if requeued:
                    enqueue(job.first_job(), job.pk)
        except IntegrityError:
            continue  # a newer job was queued meanwhile; the next sweep fails this one
        count += requeued
    return count


def resend_waiting(after):
    """Send again every queued job that waited more than ``after`` seconds; how many."""
    return sum(_resend_waiting(model, after) for model in JOB_MODELS)


def _resend_waiting(model, after=None):
    count = 0
    for job in model.objects.waiting_too_long(after):
        with transaction.atomic():
            model.objects.filter(pk=job.pk, status="queued").update(claimed_at=timezone.now())
            enqueue(job.first_job(), job.pk)
        count += 1
    return count
