"""A long take's library rows are described by a real worker after the submit, not in the
request (issue 48, item 4), on PostgreSQL + Redis."""

import pytest
from django.test import override_settings

from segmentation.models import LibrarySegment
from tests.motionlib.points_data import points_file
from tests.segmentation.integration.conftest import wait_for
from tests.segmentation.integration.test_pipeline import (
    client_for,
    label_all_and_submit,
    people,
    settled,
    upload,
)

pytestmark = pytest.mark.integration
__all__ = ["people"]


@override_settings(CUTROOM_DESCRIBE_INLINE=1000)  # 13 markers × 738 frames is more
def test_a_worker_describes_the_rows_a_submit_stored(running_workers, people):
    project, alice, bob = people
    capture = upload(client_for(alice), project, points_file("vmci", "subject1_run1.tsv")
                     .read_bytes(), name="subject1_run1.tsv")
    wait_for(lambda: settled(capture), timeout=120, what="ingest and detection")
    label_all_and_submit(client_for(bob), capture, "walk")
    rows = LibrarySegment.objects.filter(capture_id=capture)
    assert rows.exists()
    wait_for(lambda: not rows.filter(profile__isnull=True).exists(), timeout=60,
             what="the worker to describe the rows")
    assert not rows.filter(descriptor__isnull=True).exists()
