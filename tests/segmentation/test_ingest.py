"""Ingest and detection, run in-process by calling the task functions (the worker's logic;
the integration tests run the same tasks in real worker processes)."""

import numpy as np

import motionlib
from motionlib.segmenters import get_segmenter
from segmentation import tasks
from segmentation.files import storage
from segmentation.models import Capture, DetectionRun
from tests.segmentation.base import SHARED_DATA, BaseTestCase

BVH_13_29 = SHARED_DATA / "cmu" / "bvh" / "13_29.bvh"
AMC_13_30 = SHARED_DATA / "cmu" / "amc" / "13_30.amc"
ASF_13 = SHARED_DATA / "cmu" / "asf" / "13.asf"


class IngestTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        if not BVH_13_29.exists():
            self.skipTest(f"real CMU data not found at {SHARED_DATA}")
        self.login(self.bob)

    def test_it_reads_a_real_bvh_and_stores_its_metadata(self):
        capture = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        self.assertEqual(capture.status, "ready", capture.error)
        self.assertEqual((capture.format, capture.fps, capture.n_frames), ("bvh", 120.0, 4593))
        self.assertEqual((capture.n_joints, capture.rest_pose_frame), (31, 0))
        self.assertEqual(len(capture.skeleton["joints"]), 31)
        self.assertEqual(capture.skeleton["parents"][0], -1)
        self.assertAlmostEqual(capture.duration, 4593 / 120.0)

    def test_it_stores_float32_positions_for_playback(self):
        capture = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        positions = storage.load_npy(capture.positions)
        self.assertEqual((positions.shape, positions.dtype), ((4593, 31, 3), np.dtype("<f4")))

    def test_it_runs_the_projects_default_method(self):
        capture = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        run = DetectionRun.objects.get(capture=capture)
        self.assertEqual((run.method, run.status), ("default", "ready"))
        self.assertGreater(len(run.candidates), 0)
        # The stored candidates are the default method's cuts of the file as motionlib reads it.
        expected = get_segmenter("default")(**run.params).fit_predict(motionlib.read(BVH_13_29))
        self.assertEqual([c["frame"] for c in run.candidates], expected.cuts.tolist())
        for stored, confidence in zip(run.candidates, expected.confidence, strict=True):
            self.assertAlmostEqual(stored["confidence"], confidence, delta=1e-4)
        self.assertIn("total", run.timings)
        self.assertTrue(storage.load_npz(run.signals))

    def test_it_reads_amc_with_its_asf(self):
        asf = ("13.asf", ASF_13.read_bytes())
        capture = self.ingest(self.upload(AMC_13_30.read_bytes(), name="13_30.amc", asf=asf).json()["id"])
        self.assertEqual(capture.status, "ready", capture.error)
        self.assertEqual((capture.format, capture.n_frames), ("amc", 2465))

    def test_it_fails_a_truncated_bvh_with_the_reason_and_keeps_the_original(self):
        content = BVH_13_29.read_bytes()
        truncated = content[: len(content) // 2]
        capture = self.ingest(self.upload(truncated, name="13_29_cut.bvh").json()["id"])
        self.assertEqual(capture.status, "failed")
        # file:line: what — the stored original keeps its uploaded name.
        self.assertRegex(capture.error, r"^13_29_cut\.bvh:\d+: .*expected 96 values")
        with capture.original.open("rb") as handle:
            self.assertEqual(handle.read(), truncated)
        self.assertFalse(DetectionRun.objects.exists())

    def test_it_fails_a_file_that_is_not_motion_capture(self):
        capture = self.ingest(self.upload(b"<html>not a take</html>\n", name="page.bvh").json()["id"])
        self.assertEqual(capture.status, "failed")
        self.assertTrue(capture.error)

    def test_a_file_at_fault_fails_it_with_a_permanent_error(self):
        capture = self.ingest(self.upload(b"HIERARCHY\nROOT", name="broken.bvh").json()["id"])
        self.assertEqual((capture.status, capture.error_permanent), ("failed", True))

    def test_a_failed_capture_leaves_earlier_captures_untouched(self):
        good = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        self.ingest(self.upload(b"HIERARCHY\nROOT", name="broken.bvh").json()["id"])
        again = Capture.objects.get(pk=good.pk)
        self.assertEqual((again.status, again.n_frames, again.positions.name), ("ready", 4593, good.positions.name))

    def test_a_second_delivery_of_a_finished_job_does_nothing(self):
        capture = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        tasks.ingest(capture.pk)
        again = Capture.objects.get(pk=capture.pk)
        self.assertEqual((again.attempts, again.positions.name), (1, capture.positions.name))
        self.assertEqual(DetectionRun.objects.filter(capture=capture).count(), 1)

    def test_the_ingest_job_detects_at_once_and_the_queued_detect_job_then_does_nothing(self):
        capture_id = self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"]
        tasks.ingest(capture_id)
        run = DetectionRun.objects.get(capture_id=capture_id)
        self.assertEqual((run.status, run.attempts), ("ready", 1))
        # The detect message queued on commit arrives afterwards.
        tasks.detect(run.pk)
        again = DetectionRun.objects.get(pk=run.pk)
        self.assertEqual((again.attempts, again.signals.name), (1, run.signals.name))

    def test_a_run_on_demand_uses_its_own_params(self):
        capture = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        r = self.client.post(f"/api/captures/{capture.pk}/runs/", {"method": "bone_angle", "params": {"param": 0.2}}, format="json")
        tasks.detect(r.json()["id"])
        strict = DetectionRun.objects.get(pk=r.json()["id"])
        r = self.client.post(f"/api/captures/{capture.pk}/runs/", {"method": "bone_angle", "params": {"param": 1.0}}, format="json")
        tasks.detect(r.json()["id"])
        loose = DetectionRun.objects.get(pk=r.json()["id"])
        self.assertEqual((strict.status, loose.status), ("ready", "ready"))
        self.assertLess(len(strict.candidates), len(loose.candidates))

    def test_the_review_starts_from_the_latest_finished_run(self):
        capture = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        r = self.client.post(f"/api/captures/{capture.pk}/runs/", {"method": "bone_angle"}, format="json")
        tasks.detect(r.json()["id"])
        review = self.client.get(f"/api/captures/{capture.pk}/review/").json()
        self.assertEqual(review["run"], r.json()["id"])
        run = DetectionRun.objects.get(pk=r.json()["id"])
        self.assertEqual([c["frame"] for c in review["cuts"]], [c["frame"] for c in run.candidates])

    def test_a_project_with_broken_default_params_still_gets_a_ready_capture(self):
        self.project.default_method, self.project.default_params = "bone_angle", {"param": 9}
        self.project.save()
        capture = self.ingest(self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"])
        self.assertEqual(capture.status, "ready")
        run = DetectionRun.objects.get(capture=capture)
        self.assertEqual(run.status, "failed")
        self.assertIn("project default parameters: param", run.error)

    def test_a_storage_failure_fails_the_capture_instead_of_leaving_it_processing(self):
        capture_id = self.upload(BVH_13_29.read_bytes(), name="13_29.bvh").json()["id"]
        # A file where the derived-arrays folder should be: saving positions fails.
        (self.media_root / "derived").write_text("not a folder")
        with self.assertLogs("segmentation.services.jobs", "ERROR"):
            capture = self.ingest(capture_id)
        self.assertEqual(capture.status, "failed")
        self.assertIn("Ingest failed with an internal error", capture.error)
        self.assertFalse(capture.error_permanent)  # retrying once storage works may succeed
        self.assertTrue(capture.original.storage.exists(capture.original.name))
