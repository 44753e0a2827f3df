from io import StringIO

from django.core.management import call_command
from django.test import override_settings
from django.utils import timezone

from segmentation import tasks
from segmentation.models import Capture, DetectionRun
from segmentation.services import jobs
from tests.segmentation.base import BaseTestCase


class ClaimsTestCase(BaseTestCase):
    """Background jobs claim their row; a second delivery of the same job does nothing."""

    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        Capture.objects.filter(pk=self.capture.pk).update(status="queued")

    def test_only_one_claim_wins(self):
        self.assertTrue(Capture.objects.claim(self.capture.pk, "first"))
        self.assertFalse(Capture.objects.claim(self.capture.pk, "second"))
        self.assertEqual(Capture.objects.get(pk=self.capture.pk).claim_token, "first")

    def test_the_same_job_redelivered_after_its_worker_died_reclaims(self):
        Capture.objects.claim(self.capture.pk, "job-1")
        self.assertTrue(Capture.objects.claim(self.capture.pk, "job-1"))
        self.assertEqual(Capture.objects.get(pk=self.capture.pk).attempts, 2)

    @override_settings(CUTROOM_CLAIM_TIMEOUT=60)
    def test_a_stale_claim_can_be_taken_over(self):
        Capture.objects.claim(self.capture.pk, "lost")
        Capture.objects.filter(pk=self.capture.pk).update(
            claimed_at=timezone.now() - timezone.timedelta(seconds=61)
        )
        self.assertTrue(Capture.objects.claim(self.capture.pk, "rescuer"))

    def test_a_finished_job_is_never_claimed_again(self):
        Capture.objects.filter(pk=self.capture.pk).update(status="ready")
        self.assertFalse(Capture.objects.claim(self.capture.pk, "late"))

    def test_a_worker_that_lost_its_claim_cannot_store_its_result(self):
        Capture.objects.claim(self.capture.pk, "slow")
        slow = Capture.objects.get(pk=self.capture.pk)
        Capture.objects.filter(pk=self.capture.pk).update(claim_token="fast", status="ready")
        self.assertFalse(slow.fail("too late"))
        self.assertEqual(Capture.objects.get(pk=self.capture.pk).error, "")

    @override_settings(CUTROOM_MAX_ATTEMPTS=2)
    def test_a_job_that_keeps_killing_its_worker_is_marked_failed(self):
        Capture.objects.filter(pk=self.capture.pk).update(status="processing", attempts=2, claim_token="x")
        tasks.ingest.apply(args=[self.capture.pk], task_id="x")
        capture = Capture.objects.get(pk=self.capture.pk)
        self.assertEqual(capture.status, "failed")
        self.assertIn("started 3 times and never finished", capture.error)
        self.assertIn("original upload is kept", capture.error)
        self.assertFalse(capture.error_permanent)
        self.assertTrue(capture.original.storage.exists(capture.original.name))


class SweepTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.run = self.capture.runs.get()
        old = timezone.now() - timezone.timedelta(hours=2)
        DetectionRun.objects.filter(pk=self.run.pk).update(
            status="processing", claim_token="dead", claimed_at=old, attempts=1
        )

    def test_it_requeues_a_job_whose_worker_vanished(self):
        with self.captureOnCommitCallbacks() as callbacks:
            self.assertEqual(jobs.sweep(), 1)
        self.assertEqual(DetectionRun.objects.get(pk=self.run.pk).status, "queued")
        self.assertEqual(len(callbacks), 1)

    @override_settings(CUTROOM_MAX_ATTEMPTS=1)
    def test_it_fails_a_stale_job_that_used_up_its_attempts(self):
        jobs.sweep()
        run = DetectionRun.objects.get(pk=self.run.pk)
        self.assertEqual(run.status, "failed")
        self.assertIn("never finished", run.error)
        self.assertIsNotNone(run.finished_at)

    def test_it_leaves_a_fresh_claim_alone(self):
        DetectionRun.objects.filter(pk=self.run.pk).update(claimed_at=timezone.now())
        self.assertEqual(jobs.sweep(), 0)
        self.assertEqual(DetectionRun.objects.get(pk=self.run.pk).status, "processing")


    def test_the_command_sweeps(self):
        out = StringIO()
        call_command("sweep_claims", stdout=out)
        self.assertEqual(out.getvalue().strip(), "1 stale job(s) requeued or failed")
        self.assertEqual(DetectionRun.objects.get(pk=self.run.pk).status, "queued")


class LostMessageTestCase(BaseTestCase):
    """A job whose message never reached a worker (broker down at upload time)."""

    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        Capture.objects.filter(pk=self.capture.pk).update(
            status="queued", created_at=timezone.now() - timezone.timedelta(hours=1)
        )

    def test_the_sweep_sends_it_again_once(self):
        with self.captureOnCommitCallbacks() as first:
            jobs.sweep()
        with self.captureOnCommitCallbacks() as second:
            jobs.sweep()
        self.assertEqual((len(first), len(second)), (1, 0))

    def test_an_unreachable_broker_does_not_fail_the_upload(self):
        from cutroom.celery import app

        def reset_connections():
            # Connections are pooled per broker URL at first use; start afresh.
            if app._pool is not None:
                app._pool.force_close_all()
            app._pool = app.amqp._producer_pool = None

        unreachable = {"broker_url": "redis://127.0.0.1:1/0", "broker_connection_max_retries": 0}
        self.addCleanup(reset_connections)
        self.addCleanup(app.conf.update, {key: app.conf[key] for key in unreachable})
        reset_connections()
        app.conf.update(unreachable)
        self.login(self.bob)
        with self.assertLogs("segmentation.workers", "ERROR") as logs:
            with self.captureOnCommitCallbacks(execute=True):
                r = self.upload(b"HIERARCHY\n", name="offline.bvh")
        self.assertEqual(r.status_code, 201)
        self.assertIn("the sweep will retry", logs.output[0])
        self.assertEqual(Capture.objects.get(pk=r.json()["id"]).status, "queued")
