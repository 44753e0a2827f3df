"""A C3D, a Qualisys TSV and a joint-position CSV upload, each through real workers on
PostgreSQL + Redis to candidate cuts; label suggestions for a take of bare points."""

from pathlib import Path

import pytest

from segmentation import services
from segmentation.models import Capture, LibrarySegment
from tests.motionlib.points_data import HDM05, points_file
from tests.segmentation.integration.conftest import wait_for
from tests.segmentation.integration.test_pipeline import (
    client_for,
    label_all_and_submit,
    people,
    settled,
    suggested_labels,
    upload,
)

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


def test_a_worker_suggests_labels_for_a_take_of_points_of_no_known_set(running_workers, people):
    """Two vMCI runs (13 markers, no known marker set): bob labels the first, and the review
    of the second asks for suggestions, which a real worker computes from the points alone."""
    project, alice, bob = people
    services.do_add_label(project, "reach")
    first, second = (upload(client_for(alice), project, points_file("vmci", name).read_bytes(),
                            name=name) for name in ("subject1_run1.tsv", "subject1_run2.tsv"))
    wait_for(lambda: settled(first) and settled(second), timeout=120, what="ingest and detection")
    bob_client = client_for(bob)
    label_all_and_submit(bob_client, first, "reach")
    # A point take's library rows are built by a worker after the submit.
    wait_for(lambda: LibrarySegment.objects.filter(capture_id=first).exists(), timeout=120,
             what="the submitted review's library rows")
    assert suggested_labels(bob_client, second) == {"reach"}
