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
from tests.segmentation.truth_reviews import SECONDS, review_to_the_truth

pytestmark = pytest.mark.integration


def client_for(user):
    client = APIClient()
    client.force_authenticate(user)
    return client



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
