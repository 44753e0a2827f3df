"""Limits that keep one user or project from slowing the service for everyone: each
refusal is a 4xx naming the limit and its setting."""

from django.test import override_settings
from django.utils import timezone

from segmentation import services
from segmentation.errors import TooManyRequests
from segmentation.models import Capture, DetectionRun
from segmentation.services import quotas
from tests.segmentation.base import BaseTestCase, synthetic_bvh


class DetectionCostTestCase(BaseTestCase):
    """Parameter ranges bound what one detection run may cost."""

    def setUp(self):
        super().setUp()
        self.url = f"/api/captures/{self.ready_capture().pk}/runs/"
        self.login(self.bob)

    def start(self, method, **params):
        return self.client.post(self.url, {"method": method, "params": params}, format="json")

    def test_it_refuses_a_ppca_growth_step_finer_than_a_twenty_fifth_of_a_second(self):
        r = self.start("ppca", step_s=0.005)
        self.assertEqual(r.status_code, 400)
        self.assertIn("step_s: must be between 0.04 and 10, got 0.005", r.json()["detail"])

    def test_it_refuses_a_ppca_window_longer_than_ten_seconds(self):
        self.assertEqual(self.start("ppca", window_s=60).status_code, 400)

    def test_it_refuses_a_lowess_span_over_two_thousand_frames(self):
        self.assertEqual(self.start("joint_distance_pca", span=100000).status_code, 400)

    def test_it_refuses_a_refinement_window_over_two_thousand_frames(self):
        self.assertEqual(self.start("joint_distance_pca", alpha=100000).status_code, 400)

    def test_it_refuses_more_poses_per_comparison_window_than_it_can_afford(self):
        r = self.start("default", rate_hz=60, scale_min_s=20, scale_max_s=20)
        self.assertEqual(r.status_code, 400)
        self.assertIn("rate_hz * scale_max_s must be at most 600", r.json()["detail"])


@override_settings(CUTROOM_PROJECT_ACTIVE_RUNS=2)
class ActiveRunsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.url = f"/api/captures/{self.capture.pk}/runs/"
        self.login(self.bob)

    def test_it_refuses_a_run_while_the_project_has_its_limit_running(self):
        for status in ("queued", "processing"):
            DetectionRun.objects.create(capture=self.capture, method="bone_angle", status=status)
        r = self.client.post(self.url, {"method": "bone_angle"}, format="json")
        self.assertEqual(r.status_code, 429)
        self.assertEqual(r["Retry-After"], "30")
        self.assertIn("has 2 detection runs queued or running; the limit is 2 at once "
                      "(CUTROOM_PROJECT_ACTIVE_RUNS)", r.json()["detail"])

    def test_it_starts_a_run_once_one_has_finished(self):
        for status in ("queued", "ready"):
            DetectionRun.objects.create(capture=self.capture, method="bone_angle", status=status)
        r = self.client.post(self.url, {"method": "bone_angle"}, format="json")
        self.assertEqual(r.status_code, 202)


@override_settings(CUTROOM_PROJECT_ACTIVE_RUNS=2, CUTROOM_USER_ACTIVE_RUNS=3)
class UserActiveRunsTestCase(BaseTestCase):
    """Projects cost nothing to create, so one person's runs are limited across them all."""

    def start_in_new_project(self, n):
        project = services.do_create_project(self.bob, f"Bob's studio {n}")
        capture = self.ready_capture(name=f"take{n}.bvh")
        Capture.objects.filter(pk=capture.pk).update(project=project)
        return self.client.post(f"/api/captures/{capture.pk}/runs/", {"method": "bone_angle"},
                                format="json")

    def test_it_refuses_a_persons_runs_past_the_limit_whatever_the_project(self):
        self.login(self.bob)
        self.assertEqual([self.start_in_new_project(n).status_code for n in range(3)], [202] * 3)
        r = self.start_in_new_project(3)
        self.assertEqual(r.status_code, 429)
        self.assertIn("you have 3 detection runs queued or running across your projects; the "
                      "limit is 3 at once per person (CUTROOM_USER_ACTIVE_RUNS)", r.json()["detail"])

    def test_finished_runs_and_other_peoples_runs_do_not_count(self):
        self.login(self.bob)
        for n in range(2):
            self.assertEqual(self.start_in_new_project(n).status_code, 202)
        DetectionRun.objects.update(status="ready")
        capture = self.ready_capture(name="alices.bvh")
        DetectionRun.objects.create(capture=capture, method="bone_angle", created_by=self.alice)
        self.assertEqual([self.start_in_new_project(n).status_code for n in range(2, 5)], [202] * 3)


class UploadQuotaTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    @override_settings(CUTROOM_UPLOADS_PER_HOUR=2)
    def test_it_refuses_uploads_beyond_the_hourly_rate(self):
        for seed in (1, 2):
            self.assertEqual(self.upload(synthetic_bvh(seed=seed, duration=2.0)).status_code, 201)
        r = self.upload(synthetic_bvh(seed=3, duration=2.0))
        self.assertEqual(r.status_code, 429)
        self.assertIn("the limit is 2 per hour (CUTROOM_UPLOADS_PER_HOUR)", r.json()["detail"])
        self.assertGreater(int(r["Retry-After"]), 3500)

    @override_settings(CUTROOM_UPLOADS_PER_HOUR=1)
    def test_it_counts_only_the_last_hour(self):
        self.assertEqual(self.upload(synthetic_bvh(seed=1, duration=2.0)).status_code, 201)
        Capture.objects.update(created_at=timezone.now() - timezone.timedelta(minutes=61))
        self.assertEqual(self.upload(synthetic_bvh(seed=2, duration=2.0)).status_code, 201)

    @override_settings(CUTROOM_PROJECT_STORAGE_MB=1)
    def test_it_refuses_an_upload_past_the_project_storage_quota(self):
        Capture.objects.create(project=self.project, uploaded_by=self.alice, name="big.bvh",
                               checksum="big", stored_bytes=1024 * 1024 - 100)
        r = self.upload(synthetic_bvh(seed=1, duration=2.0))
        self.assertEqual(r.status_code, 413)
        self.assertIn("project 'Studio A' already store 1.0 MB", r.json()["detail"])
        self.assertIn("(CUTROOM_PROJECT_STORAGE_MB)", r.json()["detail"])
        self.assertFalse(Capture.objects.filter(uploaded_by=self.bob).exists())

    @override_settings(CUTROOM_USER_STORAGE_MB=1)
    def test_it_refuses_an_upload_past_the_user_storage_quota(self):
        Capture.objects.create(project=self.other_project, uploaded_by=self.bob, name="big.bvh",
                               checksum="big", stored_bytes=1024 * 1024 - 100)
        r = self.upload(synthetic_bvh(seed=1, duration=2.0))
        self.assertEqual(r.status_code, 413)
        self.assertIn("your uploads already store 1.0 MB", r.json()["detail"])

    def test_it_records_the_bytes_each_capture_stores(self):
        content = synthetic_bvh(seed=1, duration=2.0)
        r = self.upload(content)
        self.assertEqual(Capture.objects.get(pk=r.json()["id"]).stored_bytes, len(content))


class UploadWaitTestCase(BaseTestCase):
    """The wait a refusal names is until enough of the hour's uploads age out for this one,
    not until the oldest does (issue 48, item 12)."""

    @override_settings(CUTROOM_UPLOADS_PER_HOUR=3)
    def test_it_waits_for_as_many_uploads_to_age_as_the_file_needs(self):
        now = timezone.now()
        for minutes_ago in (50, 30, 10):
            capture = self.ready_capture(name=f"take{minutes_ago}.bvh")
            Capture.objects.filter(pk=capture.pk).update(
                uploaded_by=self.bob, created_at=now - timezone.timedelta(minutes=minutes_ago))
        with self.assertRaises(TooManyRequests) as caught:
            quotas.check_upload_rate(self.bob, uploads=2)
        # Two must age out: the one 30 minutes old does so in 30 minutes, not 10.
        self.assertAlmostEqual(caught.exception.retry_after, 30 * 60, delta=5)
        self.assertIn("try again in", str(caught.exception))
