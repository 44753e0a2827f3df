"""Two admins rename two labels to the same name at the same moment: the project row lock
makes one wait for the other, so the second sees the name taken and gets a 400 naming it,
not a 500 from the unique constraint (issue 33, item 2)."""

import pytest

from tests.segmentation.integration.conftest import at_once

pytestmark = pytest.mark.integration
ROUNDS = 5


def renaming(project, label, name):
    url = f"/api/projects/{project.pk}/labels/{label.pk}/"
    return lambda client: client.patch(url, {"name": name}, format="json")


def test_it_refuses_a_concurrent_rename_to_the_same_name_with_a_400(two_admins):
    from segmentation import services

    project, alice, rachel = two_admins
    for round_ in range(ROUNDS):
        first = services.do_add_label(project, f"first {round_}")
        second = services.do_add_label(project, f"second {round_}")
        name = f"stroll {round_}"
        responses = at_once([(alice, renaming(project, first, name)),
                             (rachel, renaming(project, second, name))])
        assert [r.status_code for r in responses] == [200, 400], [r.json() for r in responses]
        assert responses[1].json()["detail"] == f"name: the project already has a label {name!r}"
        assert project.labels.filter(name=name).count() == 1
