"""Submitting a review of a long take of many points does not describe its segments in the
web request (issue 48, item 4): every pair of 1,000 points over 160 frames took 18.6 s and
2.94 GB there, holding the database's write lock. Past CUTROOM_DESCRIBE_INLINE joint
positions the rows are stored at once and a worker's job describes them."""

from django.test import override_settings

from segmentation import tasks
from segmentation.models import LibrarySegment
from tests.motionlib.points_data import points_file
from tests.segmentation.base import BaseTestCase
from tests.segmentation.test_library import submit_review


class LongTakeLibraryTest(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.alice)
        content = points_file("vmci", "subject1_run1.tsv").read_bytes()
        self.capture = self.ingest(self.upload(content, name="run1.tsv").json()["id"])
        assert self.capture.status == "ready", self.capture.error

    def described(self):
        return sorted((r.start, r.profile is not None and r.descriptor is not None)
                      for r in LibrarySegment.objects.filter(capture=self.capture))

    @override_settings(CUTROOM_DESCRIBE_INLINE=1000)  # 13 markers × 738 frames is more
    def test_the_submit_stores_the_rows_and_a_job_describes_them(self):
        with self.captureOnCommitCallbacks(execute=False) as sent:
            submit_review(self.capture, self.bob, [300], ["walk", "punch"])
        assert self.described() == [(0, False), (300, False)]
        assert sent, "the job describing them is sent once the submit commits"
        assert tasks.describe_library(self.capture.pk) == 2
        assert self.described() == [(0, True), (300, True)]
        assert tasks.describe_library(self.capture.pk) == 0  # a second delivery: nothing to do

    def test_a_short_take_is_described_with_the_submit(self):
        submit_review(self.capture, self.bob, [300], ["walk", "punch"])
        assert self.described() == [(0, True), (300, True)]
