"""Two admins add the same label at the same moment: the project row lock makes one wait for
the other, so the second sees the label exists and gets a 400 naming it, not a 500."""

import threading

import pytest
from django.contrib.auth import get_user_model
from django.db import connection
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Membership

pytestmark = pytest.mark.integration
ROUNDS = 5


@pytest.fixture
def two_admins(transactional_db, services_env):
    users = get_user_model().objects
    alice = users.create_user("alice", password="alice-password")
    rachel = users.create_user("rachel", password="rachel-password")
    project = services.do_create_project(alice, "Studio A")
    Membership.objects.create(project=project, user=rachel, role="admin")
    return project, alice, rachel


def add_at_once(project, actors, body):
    start = threading.Barrier(len(actors))
    answers = []

    def one(actor):
        client = APIClient()
        client.force_authenticate(actor)
        start.wait()
        response = client.post(f"/api/projects/{project.pk}/labels/", body, format="json")
        answers.append((response.status_code, response.json()))
        connection.close()

    threads = [threading.Thread(target=one, args=(actor,)) for actor in actors]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    return sorted(answers, key=lambda answer: answer[0])


def test_it_refuses_a_concurrent_duplicate_label_with_a_400(two_admins):
    project, alice, rachel = two_admins
    for round_ in range(ROUNDS):
        name = f"walk {round_}"
        answers = add_at_once(project, [alice, rachel], {"name": name})
        assert [code for code, _ in answers] == [201, 400], answers
        assert answers[1][1]["detail"] == f"name: the project already has a label {name!r}"
        assert project.labels.filter(name=name).count() == 1
    # Positions stay one per label: each add saw the others' labels.
    assert sorted(project.labels.values_list("position", flat=True)) == list(range(ROUNDS))
