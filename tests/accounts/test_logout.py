from django.test import Client

from tests.segmentation.base import BaseTestCase


class LogoutTestCase(BaseTestCase):
    def browser(self):
        browser = Client(enforce_csrf_checks=True)
        browser.force_login(self.bob)
        return browser

    def signed_in(self, browser):
        return browser.get("/api/me/").status_code == 200

    def test_it_refuses_to_log_out_on_get(self):
        browser = self.browser()
        r = browser.get("/logout/")
        self.assertEqual((r.status_code, r["Allow"]), (405, "POST"))
        self.assertTrue(self.signed_in(browser))

    def test_it_refuses_a_logout_post_without_the_csrf_token(self):
        browser = self.browser()
        self.assertEqual(browser.post("/logout/").status_code, 403)
        self.assertTrue(self.signed_in(browser))

    def test_it_logs_out_on_post_with_the_csrf_token(self):
        browser = self.browser()
        browser.get("/")
        token = browser.cookies["csrftoken"].value
        r = browser.post("/logout/", {"csrfmiddlewaretoken": token})
        self.assertEqual((r.status_code, r["Location"]), (302, "/login/"))
        self.assertFalse(self.signed_in(browser))

    def test_the_not_built_page_signs_out_with_a_form(self):
        browser = self.browser()
        with self.settings(FRONTEND_DIST=self.media_root / "nothing-here"):
            page = browser.get("/").content.decode()
        self.assertIn('<form method="post" action="/logout/">', page)
        self.assertIn('name="csrfmiddlewaretoken"', page)
        self.assertNotIn('href="/logout/"', page)
