"""A job that runs out of memory fails once (issue 48, item 1): the failure is stored on its
row, the worker's main process serves on, and the message is not given back to the queue.

Celery raises a pool process's MemoryError again in the worker's main process, which then
died; its unacknowledged message went back to the queue and ended the next worker too. The
worker here gives each job CUTROOM_JOB_MEMORY_MB beyond what its process holds, so label
suggestions for a take of 1,000 points (positions 24 MB as float32, twice that as the
float64 the descriptor reads) meet a real MemoryError.
"""

import time

import numpy as np
import pytest
from django.core.files.base import ContentFile

from segmentation import services
from segmentation.files import storage
from segmentation.models import Capture, LibrarySegment, SuggestionRequest
from tests.motionlib.points_data import points_file
from tests.segmentation.integration.conftest import wait_for
from tests.segmentation.integration.test_pipeline import (
    client_for,
    label_all_and_submit,
    people,
    settled,
    upload,
)

pytestmark = pytest.mark.integration
__all__ = ["people"]


def bare_point_capture(project, owner, n_frames=2000, n_points=1000):
    """A ready capture of ``n_points`` points of no known marker set, positions stored."""
    rng = np.random.default_rng(3)
    positions = (rng.normal(size=(1, n_points, 3)) * 300
                 + np.cumsum(rng.normal(size=(n_frames, 1, 3)), axis=0)).astype("<f4")
    names = [f"m{k}" for k in range(n_points)]
    capture = Capture(
        project=project, uploaded_by=owner, name="cloud.csv", format="csv", checksum="cloud",
        status="ready", fps=60.0, n_frames=n_frames, n_joints=n_points,
        skeleton={"joints": names, "parents": [-1] * n_points, "height": 1.0, "up": "y",
                  "kind": "points", "marker_set": None, "unit": "mm", "first_number": 0})
    capture.original.save("cloud.csv", ContentFile(b"frame"), save=False)
    storage.save_npy(capture.positions, "positions.npy", positions)
    capture.save()
    return capture


def received(worker, task):
    """How many times the worker was handed a message of ``task``."""
    return sum(f"Task segmentation.tasks.{task}[" in line and "received" in line.lower()
               for line in worker.log.read_text().splitlines())


def test_suggestions_out_of_memory_fail_once_and_the_worker_serves_on(workers, people):
    project, alice, bob = people
    services.do_add_label(project, "reach")
    roomy = workers.start()
    first = upload(client_for(alice), project, points_file("vmci", "subject1_run1.tsv")
                   .read_bytes(), name="subject1_run1.tsv")
    wait_for(lambda: settled(first), timeout=120, what="ingest and detection")
    bob_client = client_for(bob)
    label_all_and_submit(bob_client, first, "reach")  # the library the suggestions draw on
    # A point take's library rows are built by a worker after the submit.
    wait_for(lambda: LibrarySegment.objects.filter(capture_id=first).exists(), timeout=120,
             what="the submitted review's library rows")
    workers.kill(roomy)

    workers.env["CUTROOM_JOB_MEMORY_MB"] = "40"
    worker = workers.start()
    cloud = bare_point_capture(project, alice)
    url = f"/api/captures/{cloud.pk}/review/suggestions/"
    assert bob_client.get(url).json()["pending"] is True

    request = wait_for(lambda: SuggestionRequest.objects.filter(
        capture=cloud, failed_at__isnull=False).first(), timeout=90, what="the job to fail")
    assert "label suggestions failed" in request.error
    answer = bob_client.get(url).json()
    # Settled, and no label offered (a span whose proposal was stored before the failure
    # is listed without one).
    assert answer["pending"] is False
    assert [s["label"] for s in answer["suggestions"] if s["label"] is not None] == []

    time.sleep(5)  # time for a message given back to the queue to come round again
    assert worker.poll() is None, worker.log.read_text()[-3000:]
    assert received(worker, "suggest") == 1, worker.log.read_text()[-3000:]

    # The same worker still does the next job.
    again = upload(client_for(alice), project, points_file("vmci", "subject1_run1.tsv")
                   .read_bytes().replace(b"\n", b"\r\n"), name="again.tsv")
    wait_for(lambda: settled(again), timeout=120, what="the next job")
    assert Capture.objects.get(pk=again).status == "ready"
