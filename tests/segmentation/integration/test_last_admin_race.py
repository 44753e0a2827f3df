"""The last two admins of a project demote each other at the same moment: the project
row lock makes one wait for the other, so the second sees it is the last admin."""

import pytest

from tests.segmentation.integration.conftest import at_once

pytestmark = pytest.mark.integration
ROUNDS = 5


def each_other(project, alice, rachel, send):
    """alice and rachel each ``send(client, url)`` to the other's membership at once."""
    def to(target):
        return lambda client: send(client, f"/api/projects/{project.pk}/members/{target.pk}/")
    return sorted(r.status_code for r in at_once([(alice, to(rachel)), (rachel, to(alice))]))


def test_two_simultaneous_demotions_leave_an_admin(two_admins):
    project, alice, rachel = two_admins
    for _ in range(ROUNDS):
        codes = each_other(*two_admins,
                           lambda client, url: client.patch(url, {"role": "annotator"}, format="json"))
        # The one demoted first can no longer act as admin (403) or is the last one (400).
        assert codes[0] == 200 and codes[1] in (400, 403)
        assert project.memberships.filter(role="admin").count() == 1
        project.memberships.update(role="admin")


def test_two_simultaneous_removals_leave_an_admin(two_admins):
    project, alice, rachel = two_admins
    codes = each_other(*two_admins, lambda client, url: client.delete(url))
    assert codes[0] == 204 and codes[1] in (400, 403, 404)
    assert project.memberships.filter(role="admin").count() == 1
