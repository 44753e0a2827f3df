"""A deleted capture takes its stored files along, also when it is deleted while a worker
ingests it: the job deletes what it wrote once it finds no row to record it on (issue 48,
item 12)."""

import uuid

from django.contrib.auth import get_user_model

from segmentation import tasks
from segmentation.models import Capture, DetectionRun
from segmentation.services import captures, jobs
from tests.segmentation.base import BaseTestCase, synthetic_bvh


class CaptureFilesTestCase(BaseTestCase):
    def stored_files(self):
        return sorted(p.relative_to(self.media_root).as_posix()
                      for p in self.media_root.rglob("*") if p.is_file())

    def uploaded(self):
        self.login(self.bob)
        r = self.upload(synthetic_bvh(seed=3, duration=2.0))
        self.assertEqual(r.status_code, 201, r.content)
        return Capture.objects.get(pk=r.json()["id"])

    def test_deleting_a_ready_capture_deletes_its_files(self):
        capture = self.uploaded()
        with self.captureOnCommitCallbacks(execute=True):
            self.ingest(capture.pk)
        self.assertEqual(len(self.stored_files()), 3, self.stored_files())  # original, positions, signals
        with self.captureOnCommitCallbacks(execute=True):
            Capture.objects.get(pk=capture.pk).delete()
        self.assertEqual(self.stored_files(), [])

    def test_deleting_a_capture_while_it_is_ingested_leaves_no_file(self):
        capture = self.uploaded()
        self.assertTrue(Capture.objects.claim(capture.pk, "worker-1"))
        claimed = Capture.objects.get(pk=capture.pk)
        finish = claimed.finish

        def deleted_then_finish(**fields):
            # An admin deletes the capture after the worker parsed it, before it records it.
            with self.captureOnCommitCallbacks(execute=True):
                Capture.objects.filter(pk=claimed.pk).delete()
            return finish(**fields)

        claimed.finish = deleted_then_finish
        with self.captureOnCommitCallbacks(execute=True):
            jobs.guard(captures.INGEST, claimed)
        self.assertFalse(Capture.objects.filter(pk=capture.pk).exists())
        self.assertEqual(self.stored_files(), [])
        self.assertEqual(DetectionRun.objects.count(), 0)

    def test_a_capture_deleted_before_its_job_runs_ends_the_job_quietly(self):
        capture = self.uploaded()
        with self.captureOnCommitCallbacks(execute=True):
            Capture.objects.filter(pk=capture.pk).delete()
        tasks.ingest(capture.pk)  # its message was already queued
        self.assertEqual(self.stored_files(), [])

    def test_a_run_deleted_while_it_detects_leaves_no_signals(self):
        capture = self.uploaded()
        with self.captureOnCommitCallbacks(execute=True):
            tasks.ingest(capture.pk)
        done = DetectionRun.objects.get(capture=capture)
        run = DetectionRun.objects.create(capture=capture, method=done.method, params=done.params)
        token = uuid.uuid4().hex
        self.assertTrue(DetectionRun.objects.claim(run.pk, token))
        claimed = DetectionRun.objects.get(pk=run.pk)
        finish = claimed.finish

        def deleted_then_finish(**fields):
            DetectionRun.objects.filter(pk=claimed.pk).delete()
            return finish(**fields)

        claimed.finish = deleted_then_finish
        with self.captureOnCommitCallbacks(execute=True):
            jobs.guard(captures.DETECT, claimed)
        # The original, the positions and the first run's signals; not the deleted run's.
        self.assertEqual(len(self.stored_files()), 3, self.stored_files())

    def test_a_shared_original_stays_while_another_capture_names_it(self):
        capture = self.uploaded()
        sibling = Capture.objects.create(
            project=self.project, uploaded_by=get_user_model().objects.get(username="bob"),
            name="take.bvh#2", format="bvh", checksum="other", original=capture.original.name,
            source=capture)
        with self.captureOnCommitCallbacks(execute=True):
            Capture.objects.filter(pk=capture.pk).delete()
        self.assertEqual(self.stored_files(), [sibling.original.name])
        with self.captureOnCommitCallbacks(execute=True):
            sibling.delete()
        self.assertEqual(self.stored_files(), [])
