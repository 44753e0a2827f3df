from django.test import override_settings

from tests.segmentation.base import BaseTestCase


class PagesTestCase(BaseTestCase):
    def test_the_app_needs_a_login(self):
        r = self.client.get("/captures/3/")
        self.assertEqual(r.status_code, 302)
        self.assertTrue(r["Location"].startswith("/login/?next=/captures/3/"))

    def test_the_login_page_renders(self):
        r = self.client.get("/login/")
        self.assertContains(r, "Sign in")

    def test_logging_in_leads_to_the_app(self):
        r = self.client.post("/login/", {"username": "bob", "password": "bob-password"})
        self.assertEqual((r.status_code, r["Location"]), (302, "/"))

    def test_it_says_plainly_when_the_front_end_is_not_built(self):
        self.client.force_login(self.bob)
        with override_settings(FRONTEND_DIST=self.media_root / "nothing-here"):
            r = self.client.get("/library/")
        self.assertContains(r, "The front end is not built", status_code=503)

    def test_it_serves_the_built_index_on_client_routes(self):
        dist = self.media_root / "dist"
        dist.mkdir(parents=True)
        (dist / "index.html").write_text("<div id=app>cutroom spa</div>")
        self.client.force_login(self.bob)
        with override_settings(FRONTEND_DIST=dist):
            for path in ("/", "/captures/7/review", "/projects/1/", "/library/"):
                self.assertContains(self.client.get(path), "cutroom spa", msg_prefix=path)

    def test_logout_ends_the_session(self):
        self.client.force_login(self.bob)
        r = self.client.post("/logout/")
        self.assertEqual(r["Location"], "/login/")
        self.assertEqual(self.client.get("/api/me/").status_code, 401)

    def test_the_api_schema_and_docs_are_served(self):
        self.client.force_login(self.bob)
        self.assertEqual(self.client.get("/api/schema/").status_code, 200)
        self.assertEqual(self.client.get("/api/docs/").status_code, 200)

    def test_a_token_can_be_obtained_and_used(self):
        r = self.client.post("/api/auth/token/", {"username": "bob", "password": "bob-password"}, format="json")
        token = r.json()["token"]
        self.client.credentials(HTTP_AUTHORIZATION=f"Token {token}")
        self.assertEqual(self.client.get("/api/me/").json()["username"], "bob")
