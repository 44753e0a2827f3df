"""The binary poses answer (issue 50): every pose of a range as raw little-endian float32,
streamed, for the review page of a long take."""

import json

import numpy as np
from django.test import override_settings

from segmentation.api import captures
from tests.segmentation.base import BaseTestCase


class PosesTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(n_frames=400, n_joints=5)
        self.url = f"/api/captures/{self.capture.pk}/poses/"
        self.expected = np.arange(400 * 5 * 3, dtype="<f4").reshape(400, 5, 3)
        self.login(self.bob)

    def fetch(self, **params):
        response = self.client.get(self.url, params)
        self.assertEqual(response.status_code, 200, response.content if not response.streaming else "")
        body = b"".join(response.streaming_content)
        return response, np.frombuffer(body, dtype="<f4").reshape(-1, 5, 3)

    def test_it_answers_every_pose_of_the_take_as_float32_bytes(self):
        response, poses = self.fetch()
        self.assertEqual(response["Content-Type"], "application/octet-stream")
        self.assertEqual(int(response["Content-Length"]), 400 * 5 * 3 * 4)
        self.assertEqual((response["X-Poses-Start"], response["X-Poses-Stop"], response["X-Poses-Joints"]),
                         ("0", "400", "5"))
        np.testing.assert_array_equal(poses, self.expected)

    def test_it_answers_a_range(self):
        response, poses = self.fetch(start=37, stop=41)
        self.assertEqual((response["X-Poses-Start"], response["X-Poses-Stop"]), ("37", "41"))
        np.testing.assert_array_equal(poses, self.expected[37:41])

    def test_it_has_no_frame_cap_unlike_the_json_frames(self):
        with override_settings(CUTROOM_FRAMES_PER_REQUEST=64):
            _, poses = self.fetch(start=10)
        self.assertEqual(len(poses), 390)

    def test_it_streams_in_blocks_that_join_up_exactly(self):
        original = captures.POSES_BLOCK_BYTES
        captures.POSES_BLOCK_BYTES = 7 * 5 * 3 * 4  # 7 frames a block: 400 - 3 is not a multiple
        try:
            response = self.client.get(self.url, {"start": 3})
            blocks = list(response.streaming_content)
        finally:
            captures.POSES_BLOCK_BYTES = original
        self.assertEqual(len(blocks), -(-397 // 7))
        poses = np.frombuffer(b"".join(blocks), dtype="<f4").reshape(-1, 5, 3)
        np.testing.assert_array_equal(poses, self.expected[3:])

    def test_it_answers_304_to_the_etag_it_gave(self):
        response, _ = self.fetch(start=0, stop=10)
        again = self.client.get(self.url, {"start": 0, "stop": 10}, HTTP_IF_NONE_MATCH=response["ETag"])
        self.assertEqual(again.status_code, 304)
        other = self.client.get(self.url, {"start": 0, "stop": 11}, HTTP_IF_NONE_MATCH=response["ETag"])
        self.assertEqual(other.status_code, 200)

    def test_it_refuses_a_start_past_the_end(self):
        r = self.client.get(self.url, {"start": 400})
        self.assertEqual(r.status_code, 400)
        self.assertIn("start: must be between 0 and 399, got 400", r.json()["detail"])

    def test_it_refuses_a_stop_before_the_start(self):
        r = self.client.get(self.url, {"start": 10, "stop": 10})
        self.assertEqual(r.status_code, 400)
        self.assertIn("stop: must be between 11 and 400, got 10", r.json()["detail"])

    def test_it_refuses_a_stop_past_the_end(self):
        r = self.client.get(self.url, {"stop": 401})
        self.assertEqual(r.status_code, 400)
        self.assertIn("stop: must be between 1 and 400, got 401", r.json()["detail"])

    def test_it_refuses_a_non_integer(self):
        r = self.client.get(self.url, {"start": "first"})
        self.assertEqual(r.status_code, 400)
        self.assertIn("start: must be an integer, got 'first'", r.json()["detail"])

    def test_it_refuses_a_capture_that_is_not_ready(self):
        self.capture.status = "processing"
        self.capture.save()
        r = self.client.get(self.url)
        self.assertEqual(r.status_code, 400)
        self.assertIn("processing", r.json()["detail"])

    def test_a_reviewer_of_the_project_gets_them(self):
        self.login(self.rachel)
        self.assertEqual(self.client.get(self.url, {"stop": 1}).status_code, 200)

    def test_an_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.get(self.url).status_code, 404)

    def test_a_visitor_not_signed_in_is_refused(self):
        self.client.logout()
        self.assertIn(self.client.get(self.url).status_code, (401, 403))

    def test_it_is_read_only(self):
        self.assertEqual(self.client.post(self.url).status_code, 405)

    def test_a_client_asking_for_bytes_gets_them_and_its_errors_as_json(self):
        response = self.client.get(self.url, {"stop": 2}, HTTP_ACCEPT="application/octet-stream, application/json")
        self.assertEqual(response.status_code, 200)
        self.assertEqual(len(b"".join(response.streaming_content)), 2 * 5 * 3 * 4)
        refused = self.client.get(self.url, {"start": 400}, HTTP_ACCEPT="application/octet-stream, application/json")
        self.assertEqual((refused.status_code, refused["Content-Type"]), (400, "application/json"))
        self.assertIn("start: must be between 0 and 399", refused.json()["detail"])
        alone = self.client.get(self.url, {"start": 400}, HTTP_ACCEPT="application/octet-stream")
        self.assertEqual(alone.status_code, 400)
        self.assertIn("start: must be between 0 and 399", json.loads(alone.content)["detail"])
