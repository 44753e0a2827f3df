"""Retrying a failed capture: from its stored original, by a member, only when failed."""

from segmentation import tasks
from segmentation.models import Capture
from tests.segmentation.base import BaseTestCase, synthetic_bvh


class RetryTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)
        self.content = synthetic_bvh(seed=3, duration=20.0)
        self.capture_id = self.upload(self.content, name="take.bvh").json()["id"]
        # A failure that was not the file's fault: the worker gave up on the job.
        Capture.objects.filter(pk=self.capture_id).update(
            status="failed", error="the worker was lost 3 times", attempts=3
        )

    def test_it_requeues_a_failed_capture(self):
        response = self.client.post(f"/api/captures/{self.capture_id}/retry/")
        self.assertEqual(response.status_code, 202, response.content)
        self.assertEqual((response.json()["status"], response.json()["error"]), ("queued", None))
        capture = Capture.objects.get(pk=self.capture_id)
        self.assertEqual((capture.status, capture.attempts), ("queued", 0))

    def test_it_ingests_the_stored_original_after_a_retry(self):
        self.client.post(f"/api/captures/{self.capture_id}/retry/")
        tasks.ingest(self.capture_id)
        capture = Capture.objects.get(pk=self.capture_id)
        self.assertEqual(capture.status, "ready", capture.error)
        with capture.original.open("rb") as handle:
            self.assertEqual(handle.read(), self.content)

    def test_it_requeues_when_the_same_file_is_uploaded_again(self):
        response = self.upload(self.content, name="take.bvh")
        self.assertEqual(response.status_code, 200)
        self.assertEqual((response.json()["id"], response.json()["duplicate"]), (self.capture_id, True))
        self.assertEqual(response.json()["status"], "queued")

    def test_it_refuses_to_retry_a_capture_that_did_not_fail(self):
        Capture.objects.filter(pk=self.capture_id).update(status="ready", error="")
        response = self.client.post(f"/api/captures/{self.capture_id}/retry/")
        self.assertEqual(response.status_code, 400)
        self.assertIn("only a failed capture can be retried", response.json()["detail"])
        self.assertEqual(Capture.objects.get(pk=self.capture_id).status, "ready")

    def test_it_hides_the_capture_from_an_outsider(self):
        self.login(self.charlie)
        response = self.client.post(f"/api/captures/{self.capture_id}/retry/")
        self.assertEqual(response.status_code, 404)
        self.assertEqual(Capture.objects.get(pk=self.capture_id).status, "failed")


class RetryOfferTestCase(BaseTestCase):
    """Retry is offered (``retryable``) only when reading the original again may help."""

    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def failed(self, content, name):
        capture_id = self.upload(content, name=name).json()["id"]
        tasks.ingest(capture_id)
        return self.client.get(f"/api/captures/{capture_id}/").json()

    def test_it_does_not_offer_to_retry_a_truncated_file(self):
        content = synthetic_bvh(seed=3, duration=20.0)
        body = self.failed(content[: len(content) // 2 - 7], "cut.bvh")
        assert body["status"] == "failed" and body["error"]
        assert body["retryable"] is False
        row = self.client.get("/api/captures/").json()["results"][0]
        assert (row["id"], row["retryable"]) == (body["id"], False)

    def test_it_offers_to_retry_a_failure_that_was_not_the_files(self):
        capture_id = self.upload(synthetic_bvh(seed=4, duration=20.0), name="take.bvh").json()["id"]
        Capture.objects.filter(pk=capture_id).update(
            status="failed", error="the worker was lost 3 times", attempts=3)
        assert self.client.get(f"/api/captures/{capture_id}/").json()["retryable"] is True

    def test_a_retried_file_failure_is_judged_afresh(self):
        content = synthetic_bvh(seed=5, duration=20.0)
        body = self.failed(content[: len(content) // 2 - 7], "cut.bvh")
        response = self.client.post(f"/api/captures/{body['id']}/retry/")
        assert response.status_code == 202
        assert Capture.objects.get(pk=body["id"]).error_permanent is False
