"""Recovery of background jobs (captures' ingest and conversion, detection runs): claiming
a row, renewing the claim while working, giving up on a job that keeps killing its worker,
and the sweep that requeues abandoned jobs and resends lost messages.

Tasks are sent by name (``segmentation.tasks.<name>``), so no service imports the tasks.
"""

import logging
import threading
from contextlib import contextmanager

from celery import current_app
from django.conf import settings
from django.db import connection, transaction
from django.utils import timezone

from segmentation.models import Capture, DetectionRun

log = logging.getLogger(__name__)


def send(task_name, *args, then="the sweep will retry", **options):
    """Send ``segmentation.tasks.<task_name>(*args)`` now. A broker that cannot be reached
    is logged with what happens ``then``, not raised: a job's row stays queued and the sweep
    sends it again later, so an unreachable broker costs a delay, never the request."""
    try:
        current_app.send_task(f"segmentation.tasks.{task_name}", args=args, **options)
    except Exception:
        log.exception("could not send %s%s; %s", task_name, args, then)
        return False
    return True


def enqueue(task_name, pk):
    """Send the job once the row is committed (a worker must be able to see it)."""
    # FBX conversion runs Blender: its own queue, served by its own worker.
    options = {"queue": settings.CUTROOM_CONVERT_QUEUE} if task_name == "convert" else {}
    transaction.on_commit(lambda: send(task_name, pk, **options))


def claim(model, pk, token):
    """The claimed row, or None if another worker has it or it is already done (a job
    claimed too often gives up instead)."""
    if not model.objects.claim(pk, token):
        return None
    job = model.objects.get(pk=pk)
    if exhausted(job):
        give_up(job)
        return None
    return job


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


def exhausted(job):
    """A job claimed more than CUTROOM_MAX_ATTEMPTS times: its input keeps killing workers."""
    return job.attempts > settings.CUTROOM_MAX_ATTEMPTS


def give_up(job):
    """Mark a job that never finished as failed, saying why."""
    extra = {"finished_at": timezone.now()} if isinstance(job, DetectionRun) else {}
    return job.fail(
        f"processing started {job.attempts} times and never finished (the worker was killed "
        "or lost each time); giving up. The original upload is kept.",
        **extra,
    )


def fail_at_time_limit(model, pk, token, what, setting):
    """Fail the job whose process was killed at its hard time limit (it did not stop at
    the soft one), if it still holds the claim ``token``.

    Unlike a process that died for another reason, this job is not retried: the same
    input would run as long again. Returns whether the job was failed.
    """
    job = model.objects.filter(pk=pk, status="processing", claim_token=token).first()
    if job is None:
        return False
    extra = {"finished_at": timezone.now()} if isinstance(job, DetectionRun) else {}
    return job.fail(
        f"{killed_at_time_limit(what, setting)} The same input would run as long again, so "
        "it is not retried; try parameters that cost less, or ask the administrators to "
        "raise the limit. The original upload is kept.",
        **extra,
    )


def killed_at_time_limit(what, setting):
    """The first sentence of the error of a job killed at its hard time limit."""
    return (f"{what} stopped after its time limit of {getattr(settings, setting)} s "
            f"({setting}): it did not stop by itself, so its process was killed.")


def sweep_stale_claims():
    """Requeue jobs whose worker vanished mid-way (failing those retried too often) and
    resend jobs queued for longer than the claim timeout.

    Returns the number of jobs requeued, failed or resent.
    """
    count = 0
    for model, task_name in ((Capture, Capture.first_job), (DetectionRun, "detect")):
        count += _resend_waiting(model, task_name)
        count += _rescue_stale(model, task_name)
    return count


def _resend_waiting(model, task_name):
    count = 0
    for job in model.objects.waiting_too_long():
        with transaction.atomic():
            model.objects.filter(pk=job.pk, status="queued").update(claimed_at=timezone.now())
            enqueue(_job_name(task_name, job), job.pk)
        count += 1
    return count


def _job_name(task_name, job):
    return task_name(job) if callable(task_name) else task_name


def _rescue_stale(model, task_name):
    count = 0
    for job in model.objects.stale():
        if job.attempts >= settings.CUTROOM_MAX_ATTEMPTS:
            count += give_up(job)
            continue
        with transaction.atomic():
            requeued = model.objects.filter(
                pk=job.pk, status="processing", claim_token=job.claim_token
            ).update(status="queued", claim_token="", claimed_at=timezone.now())
            if requeued:
                enqueue(_job_name(task_name, job), job.pk)
        count += requeued
    return count
