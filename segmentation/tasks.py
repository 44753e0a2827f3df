"""Background jobs. Like views: they take ids, claim the row, and call the services.

A job message may arrive twice (two workers, a redelivery after a worker died); the
conditional claim on the row makes the second delivery a no-op unless the first one was
abandoned. Failures are stored on the row (``status="failed"``, ``error``), never only
logged.
"""

import uuid

from celery import shared_task
from celery.signals import worker_ready

from segmentation import services
from segmentation.models import Capture, DetectionRun
from segmentation.services.captures import exhausted, give_up


def _claim(model, pk, task):
    """The claimed row, or None if another worker has it or it is already done."""
    token = task.request.id or uuid.uuid4().hex
    if not model.objects.claim(pk, token):
        return None
    job = model.objects.get(pk=pk)
    if exhausted(job):
        give_up(job)
        return None
    return job


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True)
def ingest(self, capture_id):
    """Parse a capture, store its metadata and positions, then queue default detection."""
    capture = _claim(Capture, capture_id, self)
    if capture is not None:
        services.ingest_capture(capture)


@shared_task(bind=True, acks_late=True, reject_on_worker_lost=True)
def detect(self, run_id):
    """Compute a run's candidate cuts."""
    run = _claim(DetectionRun, run_id, self)
    if run is not None:
        services.detect_run(run)


@shared_task
def update_similar_index(project_id):
    """Bring a project's similar-clip index in step with its library rows."""
    from segmentation import similar_index

    similar_index.update(project_id)


@shared_task
def sweep():
    """Requeue (or fail) jobs whose claim went stale because their worker vanished."""
    return services.sweep_stale_claims()


@worker_ready.connect
def sweep_on_start(**kwargs):
    # A restarted worker first picks up whatever a killed worker left behind.
    services.sweep_stale_claims()
