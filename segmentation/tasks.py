"""Background jobs. Like views: they take ids and hand the job to the job runner
(``services.jobs``), which claims the row, guards the work and closes the row.

A job message may arrive twice (two workers, a redelivery after a worker died); the
conditional claim on the row makes the second delivery a no-op unless the first one was
abandoned. Failures are stored on the row (``status="failed"``, ``error``), never only
logged.

This module is where the app meets Celery: importing it (the app does when it is ready)
connects ``segmentation.workers`` to the broker.
"""

import logging
import resource
import threading
import time
import uuid

from celery import Task, current_app, shared_task
from celery.exceptions import SoftTimeLimitExceeded, TimeLimitExceeded
from celery.signals import worker_init, worker_process_init, worker_ready
from django.conf import settings
from django.db import connection

from segmentation import workers
from segmentation.services import adaptation, captures, health, jobs, library
from segmentation.services.convert import CONVERT
from segmentation.similar import suggestions, updates

log = logging.getLogger(__name__)


def send(task_name, args, options):
    """Send task ``segmentation.tasks.<task_name>`` by name (the sender need not import it)."""
    current_app.send_task(f"segmentation.tasks.{task_name}", args=args, **options)


def ping():
    """Connect to the broker once; the transport's name (the health check's broker line)."""
    with current_app.connection_for_write() as conn:
        conn.ensure_connection(max_retries=1, timeout=5)
        return conn.transport_cls


workers.connect(send, stopped=SoftTimeLimitExceeded, ping=ping)


class OutOfMemory(RuntimeError):
    """A task's MemoryError, raised again as an ordinary error (see ContainedTask)."""


class ContainedTask(Task):
    """A task whose failure, whatever it is, ends that task only.

    Celery hands a MemoryError from a pool process to the worker's main process and raises
    it there (``celery.worker.request``): the worker dies, its unacknowledged message goes
    back to the queue and ends the next worker too. Raised again as OutOfMemory (the
    original dropped, with the frames holding what filled the memory), it is an ordinary
    failure: logged, the message acknowledged, the worker serving on.
    """

    def __call__(self, *args, **kwargs):
        try:
            return super().__call__(*args, **kwargs)
        except MemoryError:
            log.error("%s%s ran out of memory", self.name, args)
        raise OutOfMemory(f"{self.name}{args} ran out of memory")


class JobTask(ContainedTask):
    """A task that runs one job of ``kind`` (``services.jobs.Kind``), the row whose id is
    its first argument.

    Celery kills the process of a job still running at its hard time limit (it did not
    stop at the soft one). That is deterministic for the same input, so the job fails at
    once, naming the limit, instead of being retried until CUTROOM_MAX_ATTEMPTS.
    """

    kind = None

    def run_job(self, pk):
        jobs.run(self.kind, pk, self.request.id or uuid.uuid4().hex)

    def on_failure(self, exc, task_id, args, kwargs, einfo):
        # Called in the worker's main process (the pool process is gone).
        if not isinstance(exc, TimeLimitExceeded) or self.kind is None:
            return
        try:
            jobs.fail_at_time_limit(self.kind, args[0], task_id)
        except Exception:  # the claim goes stale and the sweep takes over, as before
            log.exception("could not fail %s %s after its time limit", self.name, args[0])
        finally:
            connection.close()


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True, base=JobTask,
             kind=captures.INGEST)
def ingest(self, capture_id):
    """Parse a capture, store its metadata and positions, then queue default detection."""
    self.run_job(capture_id)


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True,
             time_limit=settings.CUTROOM_CONVERT_TIME_LIMIT, base=JobTask,
             kind=CONVERT)
def convert(self, capture_id):
    """Read an FBX capture with Blender (convert queue), then queue each animation's ingest."""
    self.run_job(capture_id)


@worker_process_init.connect
def limit_job_memory(**kwargs):
    """Give each pool process CUTROOM_JOB_MEMORY_MB of address space beyond what it holds
    now: a job past it meets a MemoryError (and fails) before the OOM killer picks a
    process to end, which may be the worker's main one. Not in the convert worker, whose
    Blender child would inherit the limit.

    BLAS and OpenMP run on one thread, and each BLAS library (numpy's, scipy's, faiss's) has
    done one matrix product, before the limit is measured: OpenBLAS starts its threads and
    maps its work buffer on a process's first product, and when either fails under the
    limit it waits for good instead of raising. A pool process runs one job, so the threads
    bought little."""
    if not settings.CUTROOM_JOB_MEMORY_MB or settings.CUTROOM_CONVERT_WORKER:
        return
    _warm_blas()
    with open("/proc/self/statm") as statm:
        held = int(statm.read().split()[0]) * resource.getpagesize()
    limit = held + settings.CUTROOM_JOB_MEMORY_MB * 2**20
    resource.setrlimit(resource.RLIMIT_AS, (limit, resource.getrlimit(resource.RLIMIT_AS)[1]))


def _warm_blas():
    import faiss
    import numpy as np
    import scipy.linalg.blas
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1)
    a = np.ones((256, 256))
    a @ a
    scipy.linalg.blas.dgemm(1.0, a, a)
    index = faiss.IndexFlatL2(16)  # at 20 queries and more faiss's search is a product
    index.add(np.ones((64, 16), dtype="float32"))
    index.search(np.ones((32, 16), dtype="float32"), 1)


@worker_process_init.connect
def start_blender(**kwargs):
    # The convert worker loads Blender as its pool process starts, not on its first file (in
    # the background: a pool process must report for work within seconds).
    if settings.CUTROOM_CONVERT_WORKER:
        threading.Thread(target=_warm_blender, daemon=True).start()


def _warm_blender():
    from motionlib.errors import CaptureError
    from motionlib.io.blender import shared

    started = time.perf_counter()
    try:
        shared().start()
    except CaptureError as exc:  # the first file will try again, and fail with the reason
        log.warning("Blender did not start: %s", exc)
        return
    log.info("Blender ready in %.1f s (pid %s)", time.perf_counter() - started, shared().pid)


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True, base=JobTask,
             kind=captures.DETECT)
def detect(self, run_id):
    """Compute a run's candidate cuts."""
    self.run_job(run_id)


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True, base=JobTask,
             kind=adaptation.RETRAIN)
def retrain(self, model_id):
    """Train a project's cut model from its reviewed takes (one at a time per project:
    the claim fails while another training of the project runs, which starts this one
    when it ends)."""
    self.run_job(model_id)


class SuggestTask(ContainedTask):
    """Label suggestions: a job whose process died (killed for its memory, say) fails once,
    stored on its request's row; its message is not given back to the queue (the review
    page asks again later, see ``suggestions.ask``)."""

    def on_failure(self, exc, task_id, args, kwargs, einfo):
        # In the worker's main process when the pool process is gone.
        try:
            suggestions.failed(*args[:2], f"label suggestions failed: {type(exc).__name__}")
        except Exception:
            log.exception("could not store the failure of suggestions %s", args)
        finally:
            connection.close()


@shared_task(acks_late=True, reject_on_worker_lost=False, base=SuggestTask)
def suggest(capture_id, annotator_id):
    """Compute and store the label suggestions an annotator's review of a capture lacks
    (idempotent: a second delivery finds them stored)."""
    return suggestions.fill_by_id(capture_id, annotator_id)


@shared_task(acks_late=True, reject_on_worker_lost=False, base=ContainedTask)
def refresh_library(capture_id):
    """Build and describe a capture's library rows after a submit or gold save, off the
    request (a take of points, or a long one); a second delivery builds them again."""
    return library.build_library(capture_id)


@shared_task(acks_late=True, reject_on_worker_lost=False, base=ContainedTask)
def describe_library(capture_id):
    """Compute the motion descriptors of a long capture's library rows, off the request
    that made them (idempotent: described rows are left alone)."""
    return library.describe_library(capture_id)


@shared_task(base=ContainedTask)
def update_similar_index(project_id):
    """Bring a project's similar-clip index in step with its library rows."""
    updates.update(project_id)


@shared_task(base=ContainedTask)
def sweep():
    """Requeue (or fail) jobs whose claim went stale because their worker vanished."""
    return jobs.sweep()


@worker_init.connect
def apply_time_limits(**kwargs):
    """Per-task time limits from the worker's own settings: a soft limit (the job stops
    and fails with a message), then a hard one CUTROOM_TIME_LIMIT_GRACE s later (its
    process is killed and the job fails, see JobTask).

    Set here rather than on the decorators, where the sending process would write its
    own values into each message."""
    for task, seconds in (
        (ingest, settings.CUTROOM_INGEST_TIME_LIMIT),
        (detect, settings.CUTROOM_DETECT_TIME_LIMIT),
        (retrain, settings.CUTROOM_RETRAIN_TIME_LIMIT),
        (suggest, settings.CUTROOM_SUGGEST_TIME_LIMIT),
        (sweep, 60),
    ):
        task.soft_time_limit = seconds
        task.time_limit = seconds + settings.CUTROOM_TIME_LIMIT_GRACE


@worker_ready.connect
def sweep_on_start(**kwargs):
    # A restarted worker first picks up whatever a killed worker left behind.
    jobs.sweep()


@worker_ready.connect
def start_heartbeat(sender, **kwargs):
    # The health endpoint's sign that this worker is alive, and which queues it serves.
    worker = sender.controller
    health.beat(worker.hostname, sorted(sender.app.amqp.queues.consume_from),
                worker.concurrency)
