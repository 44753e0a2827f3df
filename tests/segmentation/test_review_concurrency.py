from segmentation.models import Cut
from tests.segmentation.base import BaseTestCase


class ReviewConcurrencyTestCase(BaseTestCase):
    """Two browser tabs of the same annotator, both at version 1."""

    def test_it_refuses_the_second_write_based_on_the_same_version(self):
        capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        url = f"/api/captures/{capture.pk}/review/"
        self.login(self.bob)
        self.client.post(url)

        first = self.client.post(url + "cuts/", {"frame": 150, "version": 1}, format="json")
        second = self.client.post(url + "cuts/", {"frame": 250, "version": 1}, format="json")

        self.assertEqual(first.status_code, 201)
        self.assertEqual(second.status_code, 409)
        body = second.json()
        self.assertIn("version 2", body["detail"])
        self.assertEqual(body["review"]["version"], 2)
        self.assertEqual([c["frame"] for c in body["review"]["cuts"]], [100, 150, 200])
        # Nothing lost, nothing merged: the first write stands, the second never happened.
        self.assertFalse(Cut.objects.filter(frame=250).exists())

    def test_the_refused_client_can_redo_its_change_on_the_current_version(self):
        capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        url = f"/api/captures/{capture.pk}/review/"
        self.login(self.bob)
        self.client.post(url)
        self.client.post(url + "cuts/", {"frame": 150, "version": 1}, format="json")
        current = self.client.post(url + "cuts/", {"frame": 250, "version": 1}, format="json").json()
        retry = self.client.post(
            url + "cuts/", {"frame": 250, "version": current["review"]["version"]}, format="json"
        )
        self.assertEqual(retry.status_code, 201)
        self.assertEqual([c["frame"] for c in retry.json()["cuts"]], [100, 150, 200, 250])
