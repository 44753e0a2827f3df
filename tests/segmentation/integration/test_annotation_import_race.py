"""An import and an edit of the same review at the same moment, both based on version 1,
on PostgreSQL: one wins, the other gets 409, and the review is exactly the winner's."""

import threading

import pytest
from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile
from django.db import connection
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Capture, DetectionRun, Review

pytestmark = pytest.mark.integration

CSV = b"take,start_frame,end_frame,label\nt.bvh,0,300,walk\nt.bvh,300,1000,Walk\n"


@pytest.fixture
def started(transactional_db, services_env):
    alice = get_user_model().objects.create_user("alice", password="alice-password")
    project = services.do_create_project(alice, "Studio A")
    services.do_add_label(project, "walk", "#2563eb", "1")
    capture = Capture.objects.create(
        project=project, name="t.bvh", format="bvh", checksum="t", status="ready",
        fps=120.0, n_frames=1000, n_joints=2,
    )
    DetectionRun.objects.create(capture=capture, method="bone_angle", status="ready",
                                candidates=[{"frame": 500, "confidence": 0.9}])
    client = APIClient()
    client.force_authenticate(alice)
    client.post(f"/api/captures/{capture.pk}/review/")
    return alice, capture


def test_an_import_and_an_edit_at_once_one_wins_and_the_other_gets_409(started):
    alice, capture = started
    url = f"/api/captures/{capture.pk}/"
    start = threading.Barrier(2)
    responses = {}

    def send(kind):
        client = APIClient()
        client.force_authenticate(alice)
        start.wait()
        if kind == "import":
            responses[kind] = client.post(url + "annotations/import/", {
                "file": SimpleUploadedFile("labels.csv", CSV), "version": 1,
                "mapping": '{"Walk": "walk"}'}, format="multipart")
        else:
            responses[kind] = client.post(url + "review/cuts/", {"frame": 900, "version": 1},
                                          format="json")
        connection.close()

    threads = [threading.Thread(target=send, args=(k,)) for k in ("import", "edit")]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)

    codes = {k: r.status_code for k, r in responses.items()}
    assert sorted(codes.values()) in ([200, 409], [201, 409]), codes
    review = Review.objects.get(capture=capture)
    segments = [(a, b, label) for _, a, b, label in review.segments()]
    if codes["import"] == 200:
        assert segments == [(0, 300, "walk"), (300, 1000, "walk")]
        event = review.events.get(action="import")
        assert event.after["mapping"] == {"Walk": "walk"}
    else:
        assert segments == [(0, 500, None), (500, 900, None), (900, 1000, None)]
        assert not review.events.filter(action="import").exists()
