"""The last two admins of a project demote each other at the same moment: the project
row lock makes one wait for the other, so the second sees it is the last admin."""

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


def race(project, pairs, send):
    """Run ``send(client, target)`` for each (actor, target) pair at the same moment."""
    start = threading.Barrier(len(pairs))
    codes = []

    def one(actor, target):
        client = APIClient()
        client.force_authenticate(actor)
        start.wait()
        codes.append(send(client, f"/api/projects/{project.pk}/members/{target.pk}/").status_code)
        connection.close()

    threads = [threading.Thread(target=one, args=pair) for pair in pairs]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    return sorted(codes)


def test_two_simultaneous_demotions_leave_an_admin(two_admins):
    project, alice, rachel = two_admins
    for _ in range(ROUNDS):
        codes = race(project, [(alice, rachel), (rachel, alice)],
                     lambda client, url: client.patch(url, {"role": "annotator"}, format="json"))
        # The one demoted first can no longer act as admin (403) or is the last one (400).
        assert codes[0] == 200 and codes[1] in (400, 403)
        assert project.memberships.filter(role="admin").count() == 1
        project.memberships.update(role="admin")


def test_two_simultaneous_removals_leave_an_admin(two_admins):
    project, alice, rachel = two_admins
    codes = race(project, [(alice, rachel), (rachel, alice)],
                 lambda client, url: client.delete(url))
    assert codes[0] == 204 and codes[1] in (400, 403, 404)
    assert project.memberships.filter(role="admin").count() == 1
