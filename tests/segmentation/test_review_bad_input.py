from tests.segmentation.base import BaseTestCase


class ReviewBadInputTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        self.url = f"/api/captures/{self.capture.pk}/review/"
        self.login(self.bob)
        self.review = self.client.post(self.url).json()

    def assert_refused(self, response, field, text):
        self.assertEqual(response.status_code, 400, response.content)
        body = response.json()
        self.assertIn(text, body["detail"])
        self.assertIn(field, body)

    def test_it_refuses_a_cut_outside_the_take(self):
        r = self.client.post(self.url + "cuts/", {"frame": 400, "version": 1}, format="json")
        self.assert_refused(r, "frame", "between 1 and 399, got 400")

    def test_it_refuses_a_cut_on_another_cut(self):
        r = self.client.post(self.url + "cuts/", {"frame": 200, "version": 1}, format="json")
        self.assert_refused(r, "frame", "already a cut at frame 200")

    def test_it_refuses_a_write_without_a_version(self):
        r = self.client.post(self.url + "cuts/", {"frame": 150}, format="json")
        self.assert_refused(r, "version", "version")

    def test_it_refuses_an_unknown_label(self):
        r = self.client.patch(self.url + "segments/0/", {"label": "dance", "version": 1}, format="json")
        self.assert_refused(r, "label", "'dance' is not a label of this project (walk, punch)")

    def test_it_refuses_a_missing_segment(self):
        r = self.client.patch(self.url + "segments/9/", {"label": "walk", "version": 1}, format="json")
        self.assert_refused(r, "index", "no segment 9")

    def test_it_refuses_both_fate_and_frame(self):
        cut = self.review["cuts"][0]["id"]
        r = self.client.patch(f"{self.url}cuts/{cut}/", {"fate": "deleted", "frame": 5, "version": 1}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("either fate or frame", r.json()["detail"])

    def test_it_refuses_an_unknown_fate(self):
        cut = self.review["cuts"][0]["id"]
        r = self.client.patch(f"{self.url}cuts/{cut}/", {"fate": "moved", "version": 1}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("fate", r.json())

    def test_a_refused_write_does_not_bump_the_version(self):
        self.client.post(self.url + "cuts/", {"frame": 400, "version": 1}, format="json")
        self.assertEqual(self.client.get(self.url).json()["version"], 1)
