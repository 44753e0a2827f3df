"""``GET /api/health/`` with real workers: a running worker's heartbeat makes its queue
healthy, and a killed one is reported gone once its heartbeat is stale."""

import pytest
from rest_framework.test import APIClient

from tests.segmentation.integration.conftest import wait_for

pytestmark = pytest.mark.integration


def health():
    return APIClient().get("/api/health/").json()["checks"]


def test_a_killed_worker_is_reported_gone(workers, settings):
    settings.CELERY_TASK_DEFAULT_QUEUE = workers.queue
    settings.CUTROOM_HEARTBEAT_STALE = 4
    workers.env["CUTROOM_HEARTBEAT_SECONDS"] = "1"
    worker = workers.start()
    alive = wait_for(lambda: health()["workers"]["ok"] and health()["workers"],
                     what="the worker's heartbeat")
    assert (alive["workers"], alive["processes"]) == (1, 1)
    assert health()["broker"]["ok"] and health()["database"]["ok"]
    workers.kill(worker)
    gone = wait_for(lambda: not health()["workers"]["ok"] and health()["workers"], timeout=30,
                    what="the killed worker to be reported gone")
    assert f"no worker of the queue '{workers.queue}' was heard of in the last 4 s" in gone["error"]
