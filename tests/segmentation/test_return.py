from segmentation.models import CaptureAgreement, LibrarySegment, Review
from tests.segmentation.base import BaseTestCase


class ReturnTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.login(self.bob)
        self.review_url = f"/api/captures/{self.capture.pk}/review/"
        self.client.post(self.review_url)
        self.client.patch(self.review_url + "segments/0/", {"label": "walk", "version": 1}, format="json")
        self.client.post(self.review_url + "submit/", {"version": 2}, format="json")
        self.review = Review.objects.get(capture=self.capture, annotator=self.bob)

    def give_back(self, comment="Cut 2 is late by 20 frames", user=None):
        self.login(user or self.rachel)
        url = f"/api/captures/{self.capture.pk}/reviews/{self.review.pk}/return/"
        return self.client.post(url, {"comment": comment}, format="json")

    def test_reviewer_returns_a_submitted_review_with_a_comment(self):
        r = self.give_back()
        self.assertEqual((r.status_code, r.json()["status"]), (200, "returned"))
        self.assertEqual(r.json()["return_comment"], "Cut 2 is late by 20 frames")

    def test_annotator_sees_the_comment_in_the_queue(self):
        self.give_back()
        self.login(self.bob)
        (item,) = self.client.get("/api/queue/").json()
        self.assertEqual((item["state"], item["review"]["return_comment"]),
                         ("returned", "Cut 2 is late by 20 frames"))

    def test_annotator_edits_and_resubmits_a_returned_review(self):
        version = self.give_back().json()["version"]
        self.login(self.bob)
        r = self.client.post(self.review_url + "cuts/", {"frame": 250, "version": version}, format="json")
        self.assertEqual(r.status_code, 201)
        r = self.client.post(self.review_url + "submit/", {"version": version + 1}, format="json")
        self.assertEqual(r.json()["status"], "submitted")

    def test_the_audit_log_records_return_and_resubmit(self):
        version = self.give_back().json()["version"]
        self.login(self.bob)
        self.client.post(self.review_url + "submit/", {"version": version}, format="json")
        actions = [e["action"] for e in self.client.get(self.review_url + "events/").json()]
        self.assertEqual(actions[-2:], ["return", "resubmit"])

    def test_a_returned_review_leaves_the_library_and_agreement(self):
        self.assertTrue(LibrarySegment.objects.filter(review=self.review).exists())
        self.give_back()
        self.assertFalse(LibrarySegment.objects.filter(review=self.review).exists())
        self.assertEqual(CaptureAgreement.objects.get(capture=self.capture).n_reviews, 0)

    def test_annotator_cannot_return_a_review(self):
        r = self.give_back(user=self.bob)
        self.assertEqual(r.status_code, 403)
        self.review.refresh_from_db()
        self.assertEqual(self.review.status, "submitted")

    def test_it_needs_a_comment(self):
        r = self.give_back(comment="  ")
        self.assertEqual(r.status_code, 400)
        self.assertIn("comment", r.json()["detail"])

    def test_it_refuses_to_return_a_review_in_progress(self):
        self.give_back()
        r = self.give_back()
        self.assertEqual(r.status_code, 400)
        self.assertIn("only a submitted review", r.json()["detail"])

    def test_a_returned_review_cannot_be_the_source_of_gold(self):
        self.give_back()
        # rachel's own submitted review means gold could be saved, just not from bob's.
        self.client.post(self.review_url)
        self.client.post(self.review_url + "submit/", {"version": 1}, format="json")
        url = f"/api/captures/{self.capture.pk}/adjudication/"
        r = self.client.put(url, {"cuts": [], "labels": ["walk"], "version": 0,
                                  "source_review": self.review.pk}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("not a submitted review", r.json()["detail"])
