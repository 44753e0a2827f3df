import base64

import numpy as np
from django.test import override_settings

from tests.segmentation.base import BaseTestCase


class FramesTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(n_frames=400, n_joints=5)
        self.url = f"/api/captures/{self.capture.pk}/frames/"
        self.login(self.bob)

    def decode(self, body):
        data = np.frombuffer(base64.b64decode(body["data"]), dtype="<f4")
        return data.reshape(body["n_frames"], body["n_joints"], 3)

    def test_it_returns_positions_as_base64_float32(self):
        body = self.client.get(self.url, {"start": 10, "stop": 20}).json()
        self.assertEqual((body["start"], body["stop"], body["step"], body["dtype"]), (10, 20, 1, "float32"))
        expected = np.arange(400 * 5 * 3, dtype="<f4").reshape(400, 5, 3)[10:20]
        np.testing.assert_array_equal(self.decode(body), expected)

    def test_it_steps(self):
        body = self.client.get(self.url, {"start": 0, "stop": 400, "step": 100}).json()
        self.assertEqual(self.decode(body)[:, 0, 0].tolist(), [0.0, 1500.0, 3000.0, 4500.0])

    @override_settings(CUTROOM_FRAMES_PER_REQUEST=64)
    def test_it_caps_the_frames_per_request_and_says_where_it_stopped(self):
        body = self.client.get(self.url).json()
        self.assertEqual((body["start"], body["stop"], body["n_frames"]), (0, 64, 64))

    def test_it_refuses_a_start_past_the_end(self):
        r = self.client.get(self.url, {"start": 400})
        self.assertEqual(r.status_code, 400)
        self.assertIn("start: must be between 0 and 399, got 400", r.json()["detail"])

    def test_it_refuses_a_non_integer(self):
        r = self.client.get(self.url, {"step": "fast"})
        self.assertEqual(r.status_code, 400)
        self.assertIn("step: must be an integer, got 'fast'", r.json()["detail"])

    def test_it_refuses_a_capture_that_is_not_ready(self):
        self.capture.status = "failed"
        self.capture.save()
        r = self.client.get(self.url)
        self.assertEqual(r.status_code, 400)
        self.assertIn("failed", r.json()["detail"])

    def test_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.get(self.url).status_code, 404)
