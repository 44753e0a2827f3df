"""A C3D, a Qualisys TSV and a joint-position CSV upload, each through real workers on
PostgreSQL + Redis to candidate cuts."""

from pathlib import Path

import pytest

from segmentation.models import Capture
from tests.motionlib.points_data import HDM05, points_file
from tests.segmentation.integration.conftest import wait_for
from tests.segmentation.integration.test_pipeline import client_for, people, settled, upload

pytestmark = pytest.mark.integration
__all__ = ["people"]


@pytest.mark.parametrize("parts, expected", [
    (HDM05, ("c3d", 5920, 44, "plug-in gait")),
    (("vmci", "subject1_run1.tsv"), ("tsv", 738, 13, None)),
    (("utkinect", "s01_e01.csv"), ("csv", 2101, 20, "kinect v1")),
])
def test_a_point_take_upload_reaches_candidates(running_workers, people, parts, expected):
    project, alice, bob = people
    path = points_file(*parts)
    capture_id = upload(client_for(alice), project, Path(path).read_bytes(), name=path.name)

    wait_for(lambda: settled(capture_id), timeout=120, what="ingest and detection")

    capture = client_for(bob).get(f"/api/captures/{capture_id}/").json()
    assert capture["status"] == "ready", capture["error"]
    assert capture["latest_run"]["status"] == "ready", capture["latest_run"]["error"]
    assert len(capture["latest_run"]["candidates"]) > 0
    stored = Capture.objects.get(pk=capture_id)
    assert (stored.format, stored.n_frames, stored.n_joints,
            stored.skeleton["marker_set"]) == expected
