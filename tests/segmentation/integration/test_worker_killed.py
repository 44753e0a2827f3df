"""A worker SIGKILLed in the middle of a job: the job is retried, never stuck in processing."""

import os
import signal
import time

import pytest
from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Capture
from tests.segmentation.base import synthetic_bvh
from tests.segmentation.integration.conftest import wait_for

pytestmark = pytest.mark.integration


@pytest.fixture
def project_and_owner(transactional_db):
    alice = get_user_model().objects.create_user("alice", password="alice-password")
    return services.do_create_project(alice, "Studio A"), alice


@pytest.fixture(scope="module")
def long_take():
    # Long enough that ingest is still running when the test kills the worker.
    return synthetic_bvh(seed=7, duration=240.0)


def upload_and_wait_until_processing(project, owner, content):
    client = APIClient()
    client.force_authenticate(owner)
    data = {"project": project.pk, "file": SimpleUploadedFile("long.bvh", content)}
    capture_id = client.post("/api/captures/", data, format="multipart").json()["id"]
    wait_for(
        lambda: Capture.objects.get(pk=capture_id).status == "processing",
        interval=0.01, what="ingest to start",
    )
    return capture_id


def wait_ready(capture_id):
    wait_for(
        lambda: Capture.objects.get(pk=capture_id).status in ("ready", "failed"),
        timeout=90, what="ingest to finish",
    )
    return Capture.objects.get(pk=capture_id)


def test_a_killed_pool_process_gives_the_job_back_and_it_is_redone(workers, project_and_owner, long_take):
    worker = workers.start()
    capture_id = upload_and_wait_until_processing(*project_and_owner, long_take)

    [child] = workers.children(worker)
    os.kill(child, signal.SIGKILL)

    capture = wait_ready(capture_id)
    assert capture.status == "ready", capture.error
    assert capture.attempts == 2
    assert "WorkerLostError" in worker.log.read_text()


def test_a_killed_worker_leaves_no_job_stuck_in_processing(workers, project_and_owner, long_take):
    worker = workers.start()
    capture_id = upload_and_wait_until_processing(*project_and_owner, long_take)

    workers.kill(worker)
    assert Capture.objects.get(pk=capture_id).status == "processing"
    time.sleep(3.5)  # the workers' claim timeout is 3 s
    workers.start()  # a restarted worker sweeps stale claims first

    capture = wait_ready(capture_id)
    assert capture.status == "ready", capture.error
    assert capture.attempts == 2
