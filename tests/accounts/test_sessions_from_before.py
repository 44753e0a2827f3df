"""A session signed in before the accounts app left the project package names the sign-in
backend by its former path (``cutroom.accounts.backends``): it stays signed in, a new
sign-in names the current path, and the former one signs no one in itself."""

from django.test import Client

from cutroom.accounts.backends import UsernameBackend as FormerBackend
from tests.segmentation.base import BaseTestCase

FORMER = "cutroom.accounts.backends.UsernameBackend"
BACKEND_KEY = "_auth_user_backend"  # where Django keeps the path in the session


class SessionsFromBeforeTestCase(BaseTestCase):
    def test_it_keeps_a_session_that_names_the_former_backend(self):
        browser = Client()
        browser.force_login(self.bob, backend=FORMER)
        self.assertEqual(browser.session[BACKEND_KEY], FORMER)
        r = browser.get("/api/me/")
        self.assertEqual((r.status_code, r.json()["username"]), (200, "bob"))

    def test_a_new_sign_in_names_the_current_backend(self):
        browser = Client()
        r = browser.post("/login/", {"username": "bob", "password": "bob-password"})
        self.assertEqual(r.status_code, 302)
        self.assertEqual(browser.session[BACKEND_KEY], "accounts.backends.UsernameBackend")

    def test_the_former_backend_signs_no_one_in(self):
        self.assertIsNone(FormerBackend().authenticate(None, username="bob", password="bob-password"))
