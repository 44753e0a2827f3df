from tests.segmentation.base import BaseTestCase


class ReviewPermissionsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        self.url = f"/api/captures/{self.capture.pk}/review/"
        self.login(self.rachel)
        self.rachels = self.client.post(self.url).json()
        self.login(self.bob)
        self.bobs = self.client.post(self.url).json()

    def test_each_annotator_gets_their_own_review(self):
        self.assertNotEqual(self.bobs["id"], self.rachels["id"])
        self.assertEqual(self.bobs["annotator"]["username"], "bob")

    def test_it_refuses_to_change_another_annotators_cut(self):
        cut = self.rachels["cuts"][0]["id"]
        r = self.client.patch(f"{self.url}cuts/{cut}/", {"fate": "deleted", "version": 1}, format="json")
        self.assertEqual(r.status_code, 404)
        self.login(self.rachel)
        self.assertEqual(self.client.get(self.url).json()["cuts"][0]["fate"], "pending")

    def test_annotator_cannot_list_every_review(self):
        r = self.client.get(f"/api/captures/{self.capture.pk}/reviews/")
        self.assertEqual(r.status_code, 403)
        self.assertNotIn("cuts", r.content.decode())

    def test_reviewer_lists_every_review(self):
        self.login(self.rachel)
        r = self.client.get(f"/api/captures/{self.capture.pk}/reviews/")
        self.assertEqual(r.status_code, 200)
        self.assertEqual({x["annotator"]["username"] for x in r.json()}, {"bob", "rachel"})

    def test_admin_lists_every_review(self):
        self.login(self.alice)
        r = self.client.get(f"/api/captures/{self.capture.pk}/reviews/")
        self.assertEqual(len(r.json()), 2)

    def test_outsider_gets_404_for_review_and_reviews(self):
        self.login(self.charlie)
        for url in (self.url, f"/api/captures/{self.capture.pk}/reviews/", self.url + "events/"):
            self.assertEqual(self.client.get(url).status_code, 404, url)
        r = self.client.post(self.url + "cuts/", {"frame": 150, "version": 1}, format="json")
        self.assertEqual(r.status_code, 404)

    def test_anonymous_is_refused(self):
        self.client.force_authenticate(None)
        self.assertIn(self.client.get(self.url).status_code, (401, 403))
