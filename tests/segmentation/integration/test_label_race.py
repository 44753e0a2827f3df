"""Two admins add the same label at the same moment: the project row lock makes one wait for
the other, so the second sees the label exists and gets a 400 naming it, not a 500."""

import pytest

from tests.segmentation.integration.conftest import at_once

pytestmark = pytest.mark.integration
ROUNDS = 5


def adding(project, name):
    url = f"/api/projects/{project.pk}/labels/"
    return lambda client: client.post(url, {"name": name}, format="json")


def test_it_refuses_a_concurrent_duplicate_label_with_a_400(two_admins):
    project, alice, rachel = two_admins
    for round_ in range(ROUNDS):
        name = f"walk {round_}"
        add = adding(project, name)
        responses = at_once([(alice, add), (rachel, add)])
        assert [r.status_code for r in responses] == [201, 400], [r.json() for r in responses]
        assert responses[1].json()["detail"] == f"name: the project already has a label {name!r}"
        assert project.labels.filter(name=name).count() == 1
    # Positions stay one per label: each add saw the others' labels.
    assert sorted(project.labels.values_list("position", flat=True)) == list(range(ROUNDS))
