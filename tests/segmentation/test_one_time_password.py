"""A one-time password (a site admin's reset, an account a site admin made) signs in once,
to choose a new password: until then every page leads to that form and the API refuses,
and it obtains no API token."""

from django.contrib.auth import get_user_model
from django.test import Client

from cutroom.accounts import passwords
from segmentation.services import team
from tests.segmentation.base import BaseTestCase

NEW = "quiet-harbour-lantern-42"


class OneTimePasswordTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.once = passwords.reset(self.bob)
        self.browser = Client()

    def sign_in(self, password):
        return self.browser.post("/login/", {"username": "bob", "password": password, "next": "/"})

    def test_the_first_sign_in_asks_for_a_new_password(self):
        self.assertEqual(self.sign_in(self.once).status_code, 302)
        page = self.browser.get("/captures/3/")
        self.assertEqual(page.status_code, 302)
        self.assertEqual(page["Location"], "/password/new/?next=/captures/3/")
        form = self.browser.get(page["Location"])
        self.assertContains(form, "Choose your password")

    def test_the_api_refuses_until_a_new_password_is_chosen(self):
        self.sign_in(self.once)
        answer = self.browser.get("/api/projects/")
        self.assertEqual(answer.status_code, 403)
        self.assertIn("choose a new password", answer.json()["detail"])

    def test_the_new_password_replaces_the_one_time_one(self):
        self.sign_in(self.once)
        done = self.browser.post("/password/new/?next=/queue/",
                                 {"new_password1": NEW, "new_password2": NEW})
        self.assertEqual((done.status_code, done["Location"]), (302, "/queue/"))
        self.assertEqual(self.browser.get("/api/projects/").status_code, 200)  # still signed in
        self.assertFalse(Client().login(username="bob", password=self.once))
        self.assertTrue(Client().login(username="bob", password=NEW))
        again = Client()
        again.post("/login/", {"username": "bob", "password": NEW, "next": "/"})
        self.assertEqual(again.get("/queue/").status_code, 200)

    def test_it_refuses_a_weak_or_unchanged_new_password(self):
        self.sign_in(self.once)
        weak = self.browser.post("/password/new/", {"new_password1": "password123",
                                                    "new_password2": "password123"})
        self.assertContains(weak, "This password is too common.")
        same = self.browser.post("/password/new/", {"new_password1": self.once,
                                                    "new_password2": self.once})
        self.assertContains(same, "differ from the one-time password")
        self.assertEqual(self.browser.get("/api/projects/").status_code, 403)

    def test_it_obtains_no_api_token(self):
        answer = self.client.post("/api/auth/token/", {"username": "bob", "password": self.once},
                                  format="json")
        self.assertEqual(answer.status_code, 403)
        self.assertIn("one-time password", answer.json()["detail"])

    def test_an_account_a_site_admin_makes_starts_with_one(self):
        root = get_user_model().objects.create_superuser("root", password="root-long-password")
        _, once = team.do_create_account(self.project, root, "erin", "annotator")
        self.browser.post("/login/", {"username": "erin", "password": once, "next": "/"})
        self.assertEqual(self.browser.get("/")["Location"], "/password/new/?next=/")

    def test_a_chosen_password_asks_nothing(self):
        self.browser.post("/login/", {"username": "rachel", "password": "rachel-password"})
        self.assertEqual(self.browser.get("/api/projects/").status_code, 200)
