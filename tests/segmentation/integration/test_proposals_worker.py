"""An annotator's own proposed labels, computed by a real worker on PostgreSQL + Redis
(issue 47): bob's two labelled reviews give him proposals on a third take; ann, who has
no review nor gold, is proposed nothing of his."""

import pytest
from django.contrib.auth import get_user_model
from rest_framework.test import APIClient

from motionlib import synth
from segmentation import services
from segmentation.models import Capture
from tests.segmentation.base import synthetic_bvh
from tests.segmentation.integration.conftest import wait_for
from tests.segmentation.integration.test_pipeline import settled, upload

pytestmark = pytest.mark.integration

SECONDS = 30.0


def client_for(user):
    client = APIClient()
    client.force_authenticate(user)
    return client


def review_to_the_truth(project, capture, user, seed):
    _take, segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
    for _, _, action in segments:
        if not project.labels.filter(name=action).exists():
            services.do_add_label(project, action)
    review = services.get_or_create_review(capture, user)
    for cut in list(review.cuts.all()):
        services.do_change_cut(review, user, cut, review.version, fate="deleted")
    for start, _stop, _label in segments[1:]:
        services.do_insert_cut(review, user, start, review.version)
    for index, (_, _, action) in enumerate(segments):
        services.do_label_segment(review, user, index, action, review.version)
    services.do_submit_review(review, user, review.version)


def offered(client, capture):
    url = f"/api/captures/{capture}/review/suggestions/"
    client.get(url)
    wait_for(lambda: client.get(url).json()["pending"] is False, timeout=180, interval=0.5,
             what="suggestions")
    return client.get(url).json()["suggestions"]


def test_a_worker_proposes_an_annotator_their_own_labels_and_nobody_elses(running_workers):
    users = get_user_model().objects
    alice, bob, ann = (users.create_user(n) for n in ("alice", "bob", "ann"))
    project = services.do_create_project(alice, "Studio A")
    services.do_set_member(project, "bob", "annotator")
    services.do_set_member(project, "ann", "annotator")
    ids = [upload(client_for(alice), project, synthetic_bvh(seed=seed, duration=SECONDS),
                  name=f"take_{seed}.bvh") for seed in (92, 93, 94)]
    wait_for(lambda: all(settled(i) for i in ids), timeout=180, what="ingest and detection")
    for capture_id, seed in zip(ids[:2], (92, 93), strict=True):
        review_to_the_truth(project, Capture.objects.get(pk=capture_id), bob, seed)

    his = offered(client_for(bob), ids[2])
    proposed = [s for s in his if s["proposed"]]
    assert proposed, his
    assert all(0.6 <= s["probability"] <= 1 for s in proposed)
    assert {s["label"] for s in proposed} <= set(synth.ACTIONS)
    assert [s for s in offered(client_for(ann), ids[2]) if s["label"]] == []
