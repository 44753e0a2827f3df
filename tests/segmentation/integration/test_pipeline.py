"""Upload -> ingest -> detect -> review -> submit, with real workers on PostgreSQL + Redis."""

import pytest
from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile
from rest_framework.test import APIClient

from segmentation import services, tasks
from segmentation.models import Capture, DetectionRun
from tests.segmentation.base import synthetic_bvh
from tests.segmentation.integration.conftest import wait_for

pytestmark = pytest.mark.integration


@pytest.fixture
def people(transactional_db):
    users = get_user_model().objects
    alice = users.create_user("alice", password="alice-password")
    bob = users.create_user("bob", password="bob-password")
    project = services.do_create_project(alice, "Studio A")
    services.do_set_member(project, "bob", "annotator")
    services.do_add_label(project, "walk", "#2563eb", "1")
    return project, alice, bob


def client_for(user):
    client = APIClient()
    client.force_authenticate(user)
    return client


def upload(client, project, content, name="take.bvh"):
    data = {"project": project.pk, "file": SimpleUploadedFile(name, content)}
    response = client.post("/api/captures/", data, format="multipart")
    assert response.status_code == 201, response.content
    return response.json()["id"]


def settled(capture_id):
    capture = Capture.objects.get(pk=capture_id)
    run = capture.latest_run()
    return capture.status == "failed" or (run is not None and run.status in ("ready", "failed"))


def test_it_takes_an_upload_to_a_submitted_review(running_workers, people):
    project, alice, bob = people
    capture_id = upload(client_for(alice), project, synthetic_bvh(seed=3))

    wait_for(lambda: settled(capture_id), what="ingest and detection")

    bob_client = client_for(bob)
    capture = bob_client.get(f"/api/captures/{capture_id}/").json()
    assert capture["status"] == "ready", capture["error"]
    assert capture["latest_run"]["status"] == "ready", capture["latest_run"]["error"]
    review = bob_client.post(f"/api/captures/{capture_id}/review/").json()
    assert len(review["cuts"]) == len(capture["latest_run"]["candidates"]) > 0
    cut = review["cuts"][0]
    review = bob_client.patch(
        f"/api/captures/{capture_id}/review/cuts/{cut['id']}/",
        {"fate": "accepted", "version": review["version"]}, format="json",
    ).json()
    review = bob_client.patch(
        f"/api/captures/{capture_id}/review/segments/0/",
        {"label": "walk", "version": review["version"]}, format="json",
    ).json()
    submitted = bob_client.post(
        f"/api/captures/{capture_id}/review/submit/", {"version": review["version"]}, format="json"
    ).json()
    assert (submitted["status"], submitted["segments"][0]["label"]) == ("submitted", "walk")


def test_a_bad_upload_fails_with_its_reason_and_keeps_the_original(running_workers, people):
    project, alice, _ = people
    good = synthetic_bvh(seed=4)
    truncated = good[: len(good) * 2 // 3].rsplit(b"\n", 1)[0] + b"\n"
    capture_id = upload(client_for(alice), project, truncated, name="cut_short.bvh")

    wait_for(lambda: settled(capture_id), what="ingest")

    capture = Capture.objects.get(pk=capture_id)
    assert capture.status == "failed"
    assert "cut_short" in capture.error
    with capture.original.open("rb") as handle:
        assert handle.read() == truncated


def test_two_workers_given_the_same_job_process_it_once(running_workers, people):
    project, alice, _ = people
    assert len(running_workers.procs) == 2
    capture_id = upload(client_for(alice), project, synthetic_bvh(seed=5))
    for _ in range(3):  # the same job sent again while the first copy is in flight
        tasks.ingest.delay(capture_id)

    wait_for(lambda: settled(capture_id), what="ingest and detection")

    capture = Capture.objects.get(pk=capture_id)
    assert capture.status == "ready"
    assert capture.attempts == 1
    assert DetectionRun.objects.filter(capture=capture).count() == 1


def test_a_worker_computes_the_suggestions_the_page_asks_for(running_workers, people):
    """Bob's labelled first take is his library; the review of his second take asks for
    suggestions, which a real worker computes and stores while the page polls."""
    project, alice, bob = people
    for name in ("punch", "squat", "jumping_jack", "arm_circles", "idle", "kick"):
        services.do_add_label(project, name)
    first = upload(client_for(alice), project, synthetic_bvh(seed=5, duration=30.0), name="one.bvh")
    second = upload(client_for(alice), project, synthetic_bvh(seed=6, duration=30.0), name="two.bvh")
    wait_for(lambda: settled(first) and settled(second), what="ingest and detection")
    bob_client = client_for(bob)
    label_all_and_submit(bob_client, first, "squat")
    assert suggested_labels(bob_client, second) == {"squat"}


def label_all_and_submit(client, capture, label):
    """Label every segment of the capture's review ``label`` and submit it."""
    review = client.post(f"/api/captures/{capture}/review/").json()
    for index in range(len(review["segments"])):
        review = client.patch(f"/api/captures/{capture}/review/segments/{index}/",
                              {"label": label, "version": review["version"]}, format="json").json()
    client.post(f"/api/captures/{capture}/review/submit/", {"version": review["version"]},
                format="json")


def suggested_labels(client, capture):
    """The labels a real worker suggests for the capture's review, once it has: one
    suggestion for each segment of the review."""
    url = f"/api/captures/{capture}/review/suggestions/"
    assert client.get(url).json()["pending"] is True
    wait_for(lambda: client.get(url).json()["pending"] is False, timeout=120, interval=0.5,
             what="suggestions")
    body = client.get(url).json()
    segments = client.get(f"/api/captures/{capture}/review/").json()["segments"]
    assert [(s["start"], s["stop"]) for s in body["suggestions"]] == \
        [(s["start"], s["stop"]) for s in segments]
    return {s["label"] for s in body["suggestions"]}
