"""Small things a new user hit: plain "no such …" errors instead of Django's model names,
and an icon for the browser tab."""

from django.test import Client

from tests.segmentation.base import BaseTestCase


class PlainErrorsTestCase(BaseTestCase):
    def test_it_names_a_missing_cut_in_words(self):
        capture = self.ready_capture()
        self.login(self.bob)
        self.client.post(f"/api/captures/{capture.pk}/review/")
        r = self.client.patch(f"/api/captures/{capture.pk}/review/cuts/999999/",
                              {"fate": "accepted", "version": 1}, format="json")
        self.assertEqual((r.status_code, r.json()["detail"]), (404, "No such cut."))

    def test_it_names_a_missing_assignment_in_words(self):
        self.login(self.alice)
        r = self.client.delete(f"/api/projects/{self.project.pk}/assignments/999999/")
        self.assertEqual((r.status_code, r.json()["detail"]), (404, "No such assignment."))


class FaviconTestCase(BaseTestCase):
    def test_it_answers_the_browsers_own_favicon_request(self):
        r = Client().get("/favicon.ico")
        self.assertEqual((r.status_code, r["Content-Type"]), (200, "image/svg+xml"))
        self.assertIn(b"<svg", r.content)

    def test_the_sign_in_page_links_the_icon(self):
        self.assertContains(Client().get("/login/"), '<link rel="icon" href="/favicon.svg"')
