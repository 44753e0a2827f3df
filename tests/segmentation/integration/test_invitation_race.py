"""Simultaneous invitations on PostgreSQL: counted under the inviter's row lock and the
invitee's lock row, so neither limit is passed by sending them at once."""

import pytest

from segmentation import services
from tests.segmentation.integration.conftest import at_once

pytestmark = pytest.mark.integration
LIMIT, SENT = 5, 15


def invite(project, username):
    return lambda client: client.post(f"/api/projects/{project.pk}/members/",
                                      {"username": username, "role": "annotator"}, format="json")


def test_simultaneous_invitations_by_one_inviter_stop_at_the_limit(two_admins, settings):
    settings.CUTROOM_INVITATIONS_PER_HOUR = LIMIT
    project, alice, _ = two_admins
    responses = at_once([(alice, invite(project, f"person{i}")) for i in range(SENT)])
    codes = [r.status_code for r in responses]
    assert codes == [202] * LIMIT + [429] * (SENT - LIMIT), codes
    assert project.invitations.count() == LIMIT


def test_simultaneous_invitations_of_one_username_stop_at_the_limit(two_admins, settings):
    settings.CUTROOM_INVITATIONS_PER_INVITEE = LIMIT
    _, alice, rachel = two_admins
    projects = [services.do_create_project(user, f"{user.username} {i}")
                for i in range(SENT // 2 + 1) for user in (alice, rachel)][:SENT]
    calls = [(p.memberships.get().user, invite(p, "dana")) for p in projects]
    codes = [r.status_code for r in at_once(calls)]
    assert codes == [202] * LIMIT + [429] * (SENT - LIMIT), codes
