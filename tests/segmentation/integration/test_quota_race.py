"""One person's simultaneous uploads and detection runs, on PostgreSQL: the quotas count
under the project's and the user's row locks, so uploads never pass
CUTROOM_UPLOADS_PER_HOUR (over several projects) and runs started in several projects at
once never pass CUTROOM_USER_ACTIVE_RUNS."""

import pytest
from django.core.files.uploadedfile import SimpleUploadedFile

from segmentation import services
from segmentation.models import Capture, DetectionRun
from tests.segmentation.integration.conftest import at_once, new_queue, sending_to

pytestmark = pytest.mark.integration
UPLOAD_LIMIT, UPLOADS = 12, 40
RUN_LIMIT, STARTS = 3, 10


@pytest.fixture
def projects(two_admins):
    project, alice, _ = two_admins
    return [project] + [services.do_create_project(alice, f"Studio {n}") for n in range(STARTS - 1)]


def test_simultaneous_uploads_never_pass_the_hourly_limit(two_admins, projects, settings):
    settings.CUTROOM_UPLOADS_PER_HOUR = UPLOAD_LIMIT
    _, alice, _ = two_admins

    def upload(n):
        def send(client):
            body = {"project": projects[n % len(projects)].pk,
                    "file": SimpleUploadedFile(f"take{n}.bvh", f"HIERARCHY {n}".encode())}
            return client.post("/api/captures/", body, format="multipart")
        return alice, send

    with sending_to(new_queue()):  # no worker: the uploads stay queued
        codes = [r.status_code for r in at_once([upload(n) for n in range(UPLOADS)])]
    assert codes == [201] * UPLOAD_LIMIT + [429] * (UPLOADS - UPLOAD_LIMIT), codes
    assert Capture.objects.filter(uploaded_by=alice).count() == UPLOAD_LIMIT


def test_simultaneous_runs_in_many_projects_never_pass_the_per_person_limit(
        two_admins, projects, settings):
    settings.CUTROOM_USER_ACTIVE_RUNS = RUN_LIMIT
    _, alice, _ = two_admins
    captures = [Capture.objects.create(project=p, uploaded_by=alice, name="take.bvh", format="bvh",
                                       checksum=f"take-{p.pk}", status="ready", fps=120.0,
                                       n_frames=400, n_joints=2) for p in projects]

    def start(capture):
        return alice, lambda client: client.post(f"/api/captures/{capture.pk}/runs/",
                                                 {"method": "bone_angle"}, format="json")

    with sending_to(new_queue()):
        codes = [r.status_code for r in at_once([start(c) for c in captures])]
    assert codes == [202] * RUN_LIMIT + [429] * (STARTS - RUN_LIMIT), codes
    assert DetectionRun.objects.filter(created_by=alice, status="queued").count() == RUN_LIMIT
