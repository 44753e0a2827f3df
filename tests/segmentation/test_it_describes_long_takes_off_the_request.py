"""Submitting a review of a take of points builds no library row and computes no
descriptor in the web request (issue 48, item 4): describing 1,000 points over 160 frames
took 18.6 s and 2.94 GB there, holding the database's write lock. The submit answers at
once; a worker's job (``refresh_library``) builds and describes the rows. Takes of joints
are built in the request up to CUTROOM_DESCRIBE_INLINE joint positions, by the job past it."""

from django.test import override_settings

from segmentation import services, tasks
from segmentation.models import LibrarySegment
from segmentation.services.gold import do_save_gold
from tests.motionlib.points_data import points_file
from tests.segmentation.base import BaseTestCase, synthetic_bvh
from tests.segmentation.test_library import submit_review


class PointTakeLibraryTest(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.alice)
        content = points_file("vmci", "subject1_run1.tsv").read_bytes()
        self.capture = self.ingest(self.upload(content, name="run1.tsv").json()["id"])
        assert self.capture.status == "ready", self.capture.error

    def rows(self):
        return sorted((r.start, r.profile is not None and r.descriptor is not None)
                      for r in LibrarySegment.objects.filter(capture=self.capture))

    def test_the_submit_answers_without_rows_and_a_job_builds_them(self):
        review = services.get_or_create_review(self.capture, self.bob)
        for cut in list(review.cuts.all()):
            services.do_change_cut(review, self.bob, cut, review.version, fate="deleted")
        services.do_insert_cut(review, self.bob, 300, review.version)
        for index, name in enumerate(["walk", "punch"]):
            services.do_label_segment(review, self.bob, index, name, review.version)
        self.login(self.bob)
        with self.captureOnCommitCallbacks(execute=False) as sent:
            r = self.client.post(f"/api/captures/{self.capture.pk}/review/submit/",
                                 {"version": review.version}, format="json")
        self.assertEqual(r.status_code, 200, r.content)
        self.assertEqual(self.rows(), [])
        self.assertTrue(sent, "the job building them is sent once the submit commits")
        self.assertEqual(tasks.refresh_library(self.capture.pk), 2)
        self.assertEqual(self.rows(), [(0, True), (300, True)])
        self.assertEqual(tasks.refresh_library(self.capture.pk), 2)  # a second delivery
        self.assertEqual(self.rows(), [(0, True), (300, True)])

    def test_a_job_builds_the_rows_of_every_submit_so_far(self):
        submit_review(self.capture, self.bob, [300], ["walk", "punch"], worker=False)
        built = services.library._rows(self.capture)
        submit_review(self.capture, self.rachel, [200], ["punch", "walk"], worker=False)
        self.assertNotEqual(services.library._sources(self.capture), built[1])
        self.assertEqual(tasks.refresh_library(self.capture.pk), 4)
        self.assertEqual(len(self.rows()), 4)

    def test_a_gold_save_builds_its_rows_in_a_job_too(self):
        submit_review(self.capture, self.bob, [300], ["walk", "punch"])
        with self.captureOnCommitCallbacks(execute=False) as sent:
            do_save_gold(self.capture, self.rachel, [300], ["punch", "punch"], 0)
        self.assertTrue(sent)
        self.assertFalse(LibrarySegment.objects.filter(capture=self.capture, is_gold=True).exists())
        tasks.refresh_library(self.capture.pk)
        self.assertEqual(LibrarySegment.objects.filter(capture=self.capture, is_gold=True).count(), 2)


class JointTakeLibraryTest(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.alice)
        content = synthetic_bvh(seed=4, duration=4.0)
        self.capture = self.ingest(self.upload(content, name="walk.bvh").json()["id"])

    def test_a_short_take_of_joints_is_built_with_the_submit(self):
        submit_review(self.capture, self.bob, [200], ["walk", "punch"])
        self.assertEqual(LibrarySegment.objects.filter(capture=self.capture,
                                                       descriptor__isnull=False).count(), 2)

    @override_settings(CUTROOM_DESCRIBE_INLINE=1000)
    def test_a_take_past_the_setting_is_built_by_the_job(self):
        submit_review(self.capture, self.bob, [200], ["walk", "punch"], worker=False)
        self.assertFalse(LibrarySegment.objects.filter(capture=self.capture).exists())
        self.assertEqual(tasks.refresh_library(self.capture.pk), 2)
