"""Two clients write the same review at the same moment, both based on version 1."""

import threading

import pytest
from django.contrib.auth import get_user_model
from django.db import connection
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Capture, Cut, DetectionRun

pytestmark = pytest.mark.integration


@pytest.fixture
def review_url(transactional_db, services_env):
    alice = get_user_model().objects.create_user("alice", password="alice-password")
    project = services.do_create_project(alice, "Studio A")
    capture = Capture.objects.create(
        project=project, name="t.bvh", format="bvh", checksum="t", status="ready",
        fps=120.0, n_frames=1000, n_joints=2,
    )
    DetectionRun.objects.create(
        capture=capture, method="bone_angle", status="ready",
        candidates=[{"frame": 500, "confidence": 0.9}],
    )
    client = APIClient()
    client.force_authenticate(alice)
    client.post(f"/api/captures/{capture.pk}/review/")
    return alice, f"/api/captures/{capture.pk}/review/"


def test_one_concurrent_write_wins_and_the_other_gets_409(review_url):
    alice, url = review_url
    start = threading.Barrier(2)
    responses = {}

    def insert(frame):
        client = APIClient()
        client.force_authenticate(alice)
        start.wait()
        responses[frame] = client.post(url + "cuts/", {"frame": frame, "version": 1}, format="json")
        connection.close()

    threads = [threading.Thread(target=insert, args=(f,)) for f in (100, 900)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)

    codes = sorted(r.status_code for r in responses.values())
    assert codes == [201, 409]
    [winner] = [f for f, r in responses.items() if r.status_code == 201]
    [loser] = [r for r in responses.values() if r.status_code == 409]
    assert loser.json()["review"]["version"] == 2
    assert sorted(Cut.objects.values_list("frame", flat=True)) == sorted([500, winner])
