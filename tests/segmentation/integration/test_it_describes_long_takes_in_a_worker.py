"""A take of points has its library rows built and described by a real worker after the
submit, never in the request (issue 48, item 4), on PostgreSQL + Redis: the submit answers
without them, and they appear when the job has run."""

import time

import pytest

from segmentation.models import LibrarySegment
from tests.motionlib.points_data import points_file
from tests.segmentation.integration.conftest import wait_for
from tests.segmentation.integration.test_pipeline import client_for, people, settled, upload

pytestmark = pytest.mark.integration
__all__ = ["people"]


def test_a_worker_builds_the_rows_of_a_submitted_point_take(workers, people):
    project, alice, bob = people
    workers.start()
    capture = upload(client_for(alice), project, points_file("vmci", "subject1_run1.tsv")
                     .read_bytes(), name="subject1_run1.tsv")
    wait_for(lambda: settled(capture), timeout=120, what="ingest and detection")
    client = client_for(bob)
    review = client.post(f"/api/captures/{capture}/review/").json()
    for index in range(len(review["segments"])):
        review = client.patch(f"/api/captures/{capture}/review/segments/{index}/",
                              {"label": "walk", "version": review["version"]}, format="json").json()
    rows = LibrarySegment.objects.filter(capture_id=capture)
    workers.stop_all()  # so what the request itself stored shows before any job runs
    started = time.monotonic()
    r = client.post(f"/api/captures/{capture}/review/submit/", {"version": review["version"]},
                    format="json")
    assert r.status_code == 200, r.content
    assert time.monotonic() - started < 5
    assert r.json()["status"] == "submitted"
    assert not rows.exists(), "the request built library rows"
    workers.start()
    wait_for(lambda: rows.count() == len(review["segments"]), timeout=60,
             what="the worker to build the rows")
    assert not rows.filter(descriptor__isnull=True).exists()
    assert not rows.filter(profile__isnull=True).exists()
