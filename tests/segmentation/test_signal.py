import base64

import numpy as np

from tests.segmentation.base import BaseTestCase


class SignalTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(n_frames=400)
        self.url = f"/api/captures/{self.capture.pk}/signal/"
        self.login(self.bob)

    def test_it_samples_the_latest_runs_signal(self):
        body = self.client.get(self.url, {"max_points": 100}).json()
        self.assertEqual(body["run"], self.capture.latest_finished_run().pk)
        self.assertEqual((body["fps"], body["n_frames"]), (120.0, 400))
        [signal] = body["signals"]
        self.assertEqual((signal["name"], signal["start"], signal["step"]), ("q", 0, 4))
        self.assertEqual(len(signal["values"]), 100)
        expected = np.linspace(0.0, 1.0, 400)[::4]
        np.testing.assert_allclose(signal["values"], expected, atol=1e-6)

    def test_it_returns_every_frame_when_it_fits(self):
        [signal] = self.client.get(self.url).json()["signals"]
        self.assertEqual((signal["step"], len(signal["values"])), (1, 400))

    def test_it_is_empty_without_a_finished_run(self):
        self.capture.runs.update(status="failed")
        body = self.client.get(self.url).json()
        self.assertEqual((body["run"], body["signals"]), (None, []))

    def test_it_refuses_a_bad_max_points(self):
        r = self.client.get(self.url, {"max_points": 1})
        self.assertEqual(r.status_code, 400)
        self.assertIn("max_points", r.json()["detail"])

    def test_it_sends_the_values_as_float32_when_asked(self):
        [plain] = self.client.get(self.url, {"max_points": 100}).json()["signals"]
        [packed] = self.client.get(self.url, {"max_points": 100, "encoding": "float32"}).json()["signals"]
        self.assertEqual((packed["step"], packed["dtype"]), (plain["step"], "float32"))
        values = np.frombuffer(base64.b64decode(packed["data"]), dtype="<f4")
        np.testing.assert_allclose(values, plain["values"], atol=1e-6)

    def test_it_refuses_an_unknown_encoding(self):
        r = self.client.get(self.url, {"encoding": "csv"})
        self.assertEqual(r.status_code, 400)
        self.assertIn("encoding", r.json()["detail"])
