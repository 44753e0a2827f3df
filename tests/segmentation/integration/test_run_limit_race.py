"""People start detection runs of one project at the same moment: the project row lock
makes each start count the runs queued or running after the previous one was inserted,
so the project never has more than CUTROOM_PROJECT_ACTIVE_RUNS of them."""

import pytest

from segmentation.models import Capture, DetectionRun
from tests.segmentation.integration.conftest import at_once, new_queue, sending_to

pytestmark = pytest.mark.integration
LIMIT, STARTS, ROUNDS = 2, 6, 5


@pytest.fixture
def ready_capture(two_admins):
    project, alice, _ = two_admins
    return Capture.objects.create(
        project=project, uploaded_by=alice, name="take.bvh", format="bvh", checksum="take",
        status="ready", fps=120.0, n_frames=400, n_joints=2,
    )


def test_concurrent_starts_never_pass_the_project_limit(two_admins, ready_capture, settings):
    settings.CUTROOM_PROJECT_ACTIVE_RUNS = LIMIT
    _, alice, rachel = two_admins
    url = f"/api/captures/{ready_capture.pk}/runs/"

    def start(client):
        return client.post(url, {"method": "bone_angle"}, format="json")

    # No worker serves this queue: the runs stay queued, so every one counts.
    with sending_to(new_queue()):
        for _ in range(ROUNDS):
            responses = at_once([(alice, start), (rachel, start)] * (STARTS // 2))
            codes = [r.status_code for r in responses]
            assert codes == [202] * LIMIT + [429] * (STARTS - LIMIT), codes
            assert DetectionRun.objects.filter(status="queued").count() == LIMIT
            DetectionRun.objects.update(status="ready")
