"""The watchdog's question (are the workers stuck, or just busy?) and the monitor's
(``GET /api/health/``: database, broker, workers, convert worker, similar-clip indexes)."""

import io

import numpy as np
from django.conf import settings
from django.core.management import CommandError, call_command
from django.test import override_settings
from django.utils import timezone

from cutroom.celery import app
from motionlib import similarity
from segmentation.models import Capture, DetectionRun, LibrarySegment, WorkerHeartbeat
from segmentation.services import health
from segmentation.similar import descriptors, updates
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

    def test_an_fbx_waiting_for_the_convert_worker_is_not_the_workers_stall(self):
        """A conversion waits on the convert worker, or on purpose behind its uploader's
        running one: the default queue's workers are not stuck for it (issue 48, item 5)."""
        DetectionRun.objects.filter(pk=self.waiting.pk).update(status="ready", claimed_at=ago(600))
        Capture.objects.create(project=self.project, uploaded_by=self.bob, name="a.fbx",
                               format="fbx", checksum="a", original="captures/1/a.fbx",
                               created_at=ago(300))
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


@override_settings(CUTROOM_STALL_SECONDS=60, CUTROOM_CLAIM_TIMEOUT=30, CUTROOM_HEARTBEAT_STALE=60,
                   CUTROOM_INDEX_STALE_SECONDS=900)
class HealthEndpointTestCase(BaseTestCase):
    """``GET /api/health/``: what a monitor asks, without signing in."""

    def beating(self, hostname, queues, processes=2, seconds_ago=5):
        return WorkerHeartbeat.objects.create(hostname=hostname, queues=queues,
                                              processes=processes, seen_at=ago(seconds_ago))

    def workers_beating(self):
        self.beating("worker@host", [settings.CELERY_TASK_DEFAULT_QUEUE])
        self.beating("convert@host", [settings.CUTROOM_CONVERT_QUEUE])

    def health(self, expected_status):
        response = self.client.get("/api/health/")
        self.assertEqual(response.status_code, expected_status, response.content)
        return response.json()

    def test_it_answers_ok_while_everything_works(self):
        self.workers_beating()
        body = self.health(200)
        self.assertEqual((body["status"], body["failing"]), ("ok", []))
        self.assertEqual(body["checks"]["database"], {"ok": True, "vendor": "sqlite"})
        self.assertTrue(body["checks"]["broker"]["ok"])
        self.assertEqual(body["checks"]["workers"], {"ok": True, "workers": 1, "processes": 2})
        self.assertEqual(body["checks"]["convert_worker"]["slots"], 2)

    def test_it_names_workers_never_heard_of(self):
        body = self.health(503)
        self.assertEqual(body["failing"], ["workers", "convert_worker"])
        self.assertIn(f"no worker of the queue '{settings.CELERY_TASK_DEFAULT_QUEUE}' was heard "
                      "of in the last 60 s", body["checks"]["workers"]["error"])
        self.assertIn("FBX uploads wait", body["checks"]["convert_worker"]["error"])

    def test_a_worker_not_heard_of_lately_is_gone(self):
        self.workers_beating()
        WorkerHeartbeat.objects.filter(hostname="convert@host").update(seen_at=ago(120))
        self.assertEqual(self.health(503)["failing"], ["convert_worker"])

    def test_it_names_workers_that_beat_but_take_no_job(self):
        self.workers_beating()
        capture = self.ready_capture()
        Capture.objects.filter(pk=capture.pk).update(claimed_at=ago(600))
        DetectionRun.objects.filter(capture=capture).update(
            status="queued", claimed_at=None, created_at=ago(90))
        body = self.health(503)
        self.assertEqual(body["failing"], ["workers"])
        self.assertIn("a job has waited 90 s in the queue", body["checks"]["workers"]["error"])

    def test_it_names_a_broker_it_cannot_reach(self):
        self.workers_beating()
        app.conf.broker_url, previous = "redis://127.0.0.1:9//", app.conf.broker_url
        try:
            body = self.health(503)
        finally:
            app.conf.broker_url = previous
        self.assertEqual(body["failing"], ["broker"])
        self.assertIn("Connection refused", body["checks"]["broker"]["error"])

    def test_it_names_a_similar_index_that_lags_behind_the_library(self):
        self.workers_beating()
        capture = self.ready_capture()
        descriptor = np.arange((similarity.PROFILE_ROWS + 2) * 4, dtype="<f4").reshape(-1, 4)
        walk, _ = self.project.labels.get_or_create(name="walk", defaults={"color": "#2a9d8f"})
        for start in (0, 100, 200):
            segment = LibrarySegment(project=self.project, capture=capture, label=walk,
                                     start=start, stop=start + 100, duration=100 / 120,
                                     created_at=ago(1000))
            descriptors.store_descriptor(segment, descriptor + start)
            segment.save()
        body = self.health(503)
        self.assertEqual(body["failing"], ["similar_index"])
        self.assertIn(f"the similar-clip index of project(s) {self.project.pk} lacks segments "
                      "older than 900 s", body["checks"]["similar_index"]["error"])
        updates.build(self.project.pk)
        self.assertEqual(self.health(200)["checks"]["similar_index"],
                         {"ok": True, "projects": 1, "stale": []})

    def test_it_tells_a_monitor_without_signing_in_and_without_names(self):
        self.workers_beating()
        body = self.health(200)
        self.assertNotIn("worker@host", str(body))
