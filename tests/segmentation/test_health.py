"""The watchdog's question: are the workers stuck, or just busy?"""

import io

from django.core.management import CommandError, call_command
from django.test import override_settings
from django.utils import timezone

from segmentation.models import Capture, DetectionRun
from segmentation.services import health
from tests.segmentation.base import BaseTestCase


def ago(seconds):
    return timezone.now() - timezone.timedelta(seconds=seconds)


@override_settings(CUTROOM_STALL_SECONDS=60, CUTROOM_CLAIM_TIMEOUT=30)
class StalledTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        Capture.objects.filter(pk=self.capture.pk).update(claimed_at=ago(600))
        self.waiting = self.capture.runs.get()
        DetectionRun.objects.filter(pk=self.waiting.pk).update(
            status="queued", claimed_at=None, created_at=ago(90)
        )

    def running(self, claimed_seconds_ago):
        return DetectionRun.objects.create(
            capture=self.capture, method="bone_angle", status="processing",
            claim_token="t", claimed_at=ago(claimed_seconds_ago),
        )

    def test_it_finds_a_job_waiting_while_a_worker_process_is_free(self):
        self.assertIn("a job has waited 90 s in the queue", health.stalled(concurrency=2))

    def test_it_leaves_workers_alone_whose_processes_are_all_busy(self):
        # Long jobs whose heartbeat renewed their claims a moment ago.
        self.running(5)
        self.running(5)
        self.assertIsNone(health.stalled(concurrency=2))

    def test_it_leaves_alone_a_queue_that_moves(self):
        self.running(10)
        self.assertIsNone(health.stalled(concurrency=4))

    def test_it_leaves_alone_a_job_queued_a_moment_ago(self):
        DetectionRun.objects.filter(pk=self.waiting.pk).update(created_at=ago(5))
        self.assertIsNone(health.stalled(concurrency=2))

    def test_a_dead_claim_does_not_count_as_a_busy_process(self):
        self.running(120)
        self.assertIsNotNone(health.stalled(concurrency=1))


@override_settings(CUTROOM_STALL_SECONDS=60, CUTROOM_CLAIM_TIMEOUT=30)
class WatchJobsTestCase(BaseTestCase):
    """``manage.py watch_jobs``: compose's watchdog, the same look as make up's supervisor."""

    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.run_ = self.capture.runs.get()

    def watch_once(self):
        out, err = io.StringIO(), io.StringIO()
        call_command("watch_jobs", "--once", "--concurrency", "2", stdout=out, stderr=err)
        return out.getvalue()

    def test_it_requeues_the_job_of_a_process_that_died(self):
        DetectionRun.objects.filter(pk=self.run_.pk).update(
            status="processing", claim_token="t", claimed_at=ago(120), attempts=1
        )
        self.assertIn("1 stale job(s) requeued, failed or resent", self.watch_once())
        self.assertEqual(DetectionRun.objects.get(pk=self.run_.pk).status, "queued")

    def test_it_says_nothing_and_succeeds_while_jobs_move(self):
        self.assertEqual(self.watch_once(), "")

    def test_it_fails_naming_the_stall_when_the_workers_are_stuck(self):
        Capture.objects.filter(pk=self.capture.pk).update(claimed_at=ago(600))
        DetectionRun.objects.filter(pk=self.run_.pk).update(
            status="queued", claimed_at=None, created_at=ago(90)
        )
        with self.assertRaisesRegex(CommandError, "the workers are stuck: a job has waited 90 s"):
            self.watch_once()
