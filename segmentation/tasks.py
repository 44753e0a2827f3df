"""Background jobs. Like views: they take ids, claim the row, and call the services.

A job message may arrive twice (two workers, a redelivery after a worker died); the
conditional claim on the row makes the second delivery a no-op unless the first one was
abandoned. Failures are stored on the row (``status="failed"``, ``error``), never only
logged.
"""

import logging
import threading
import time
import uuid

from celery import Task, shared_task
from celery.exceptions import TimeLimitExceeded
from celery.signals import worker_init, worker_process_init, worker_ready
from django.conf import settings
from django.db import connection

from segmentation import services, similar_index, suggestions
from segmentation.models import Capture, DetectionRun, ProjectCutModel
from segmentation.services import adaptation, health, jobs
from segmentation.services.convert import convert_capture

log = logging.getLogger(__name__)


class JobTask(Task):
    """A task that works on one job row, the first argument: ``job_model``, named
    ``job_name`` in messages, under the time limit of setting ``limit_setting``.

    Celery kills the process of a job still running at its hard time limit (it did not
    stop at the soft one). That is deterministic for the same input, so the job fails at
    once, naming the limit, instead of being retried until CUTROOM_MAX_ATTEMPTS.
    """

    job_model, job_name, limit_setting = None, "", ""

    def on_failure(self, exc, task_id, args, kwargs, einfo):
        # Called in the worker's main process (the pool process is gone).
        if not isinstance(exc, TimeLimitExceeded) or self.job_model is None:
            return
        try:
            self.fail_at_time_limit(args[0], task_id)
        except Exception:  # the claim goes stale and the sweep takes over, as before
            log.exception("could not fail %s %s after its time limit", self.name, args[0])
        finally:
            connection.close()

    def fail_at_time_limit(self, pk, token):
        """Fail job ``pk`` if the task's claim ``token`` still holds it."""
        jobs.fail_at_time_limit(self.job_model, pk, token, self.job_name, self.limit_setting)


class TrainingTask(JobTask):
    """A cut-model training: killed at its hard time limit, it fails at once as other jobs
    do, and the training that waited behind it is started, as when a training ends."""

    job_model = ProjectCutModel

    def fail_at_time_limit(self, pk, token):
        adaptation.fail_at_time_limit(pk, token)


def _claim(model, pk, task):
    """The claimed row, or None if another worker has it or it is already done."""
    return jobs.claim(model, pk, task.request.id or uuid.uuid4().hex)


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True, base=JobTask,
             job_model=Capture, job_name="Ingest", limit_setting="CUTROOM_INGEST_TIME_LIMIT")
def ingest(self, capture_id):
    """Parse a capture, store its metadata and positions, then queue default detection."""
    capture = _claim(Capture, capture_id, self)
    if capture is not None:
        services.ingest_capture(capture)


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True,
             time_limit=settings.CUTROOM_CONVERT_TIME_LIMIT, base=JobTask, job_model=Capture,
             job_name="Conversion", limit_setting="CUTROOM_CONVERT_TIME_LIMIT")
def convert(self, capture_id):
    """Read an FBX capture with Blender (convert queue), then queue each animation's ingest."""
    capture = _claim(Capture, capture_id, self)
    if capture is not None:
        convert_capture(capture)


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
             job_model=DetectionRun, job_name="Detection",
             limit_setting="CUTROOM_DETECT_TIME_LIMIT")
def detect(self, run_id):
    """Compute a run's candidate cuts."""
    run = _claim(DetectionRun, run_id, self)
    if run is not None:
        services.detect_run(run)


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True, base=TrainingTask)
def retrain(self, model_id):
    """Train a project's cut model from its reviewed takes (one at a time per project:
    the claim fails while another training of the project runs, which starts this one
    when it ends)."""
    job = adaptation.claim_training(model_id, self.request.id or uuid.uuid4().hex)
    if job is not None:
        adaptation.train_project_model(job)


@shared_task(acks_late=True, reject_on_worker_lost=True)
def suggest(capture_id, annotator_id):
    """Compute and store the label suggestions an annotator's review of a capture lacks
    (idempotent: a second delivery finds them stored)."""
    return suggestions.fill_by_id(capture_id, annotator_id)


@shared_task
def update_similar_index(project_id):
    """Bring a project's similar-clip index in step with its library rows."""
    similar_index.update(project_id)


@shared_task
def sweep():
    """Requeue (or fail) jobs whose claim went stale because their worker vanished."""
    return services.sweep_stale_claims() + adaptation.sweep_stale_trainings()


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
    services.sweep_stale_claims()
    adaptation.sweep_stale_trainings()


@worker_ready.connect
def start_heartbeat(sender, **kwargs):
    # The health endpoint's sign that this worker is alive, and which queues it serves.
    worker = sender.controller
    health.beat(worker.hostname, sorted(sender.app.amqp.queues.consume_from),
                worker.concurrency)
