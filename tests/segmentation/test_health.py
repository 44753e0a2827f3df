"""The watchdog's question: are the workers stuck, or just busy?"""

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
