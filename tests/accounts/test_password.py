"""Changing one's password, and a site admin's reset: the refusals name what is wrong,
and a new password ends the account's other sessions and revokes its API tokens."""

from django.contrib.auth import get_user_model
from django.test import Client, override_settings

from accounts.models import ApiToken
from tests.segmentation.base import BaseTestCase

NEW = "quiet-harbour-lantern-42"


class PasswordChangeTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.browser = Client()
        self.browser.login(username="bob", password="bob-password")

    def change(self, current="bob-password", new=NEW, client=None):
        client = client or self.browser
        return client.post("/api/auth/password/", {"current_password": current, "new_password": new},
                           content_type="application/json")

    def test_it_changes_the_password_and_keeps_this_session_signed_in(self):
        r = self.change()
        self.assertEqual(r.status_code, 200, r.content)
        self.assertIn("Password changed", r.json()["detail"])
        self.bob.refresh_from_db()
        self.assertTrue(self.bob.check_password(NEW))
        self.assertEqual(self.browser.get("/api/me/").status_code, 200)

    def test_it_ends_the_accounts_other_sessions_and_revokes_its_tokens(self):
        elsewhere = Client()
        elsewhere.login(username="bob", password="bob-password")
        key = self.client.post("/api/auth/token/", {"username": "bob", "password": "bob-password"},
                               format="json").json()["token"]
        self.assertEqual(self.change().status_code, 200)
        self.assertEqual(elsewhere.get("/api/me/").status_code, 401)
        self.client.credentials(HTTP_AUTHORIZATION=f"Token {key}")
        self.assertEqual(self.client.get("/api/me/").status_code, 401)
        self.assertFalse(ApiToken.objects.filter(user=self.bob).exists())

    def test_it_refuses_a_wrong_current_password(self):
        r = self.change(current="not-it")
        self.assertEqual(r.status_code, 400)
        self.assertEqual(r.json()["detail"], "current_password: this is not your current password")
        self.bob.refresh_from_db()
        self.assertTrue(self.bob.check_password("bob-password"))

    def test_it_refuses_a_weak_password_saying_why(self):
        for weak, why in (("short", "too short"), ("password123", "too common"),
                          ("58217390461", "entirely numeric")):
            r = self.change(new=weak)
            self.assertEqual(r.status_code, 400, weak)
            self.assertTrue(r.json()["detail"].startswith("new_password: "), r.json())
            self.assertIn(why, r.json()["detail"])

    def test_it_refuses_the_same_password_again(self):
        r = self.change(new="bob-password")
        self.assertIn("new_password: must differ", r.json()["detail"])

    def test_it_changes_only_the_callers_own_password(self):
        # Rachel's password does not unlock Bob's account, and no field names another user.
        r = self.browser.post("/api/auth/password/", {"current_password": "rachel-password",
                                                      "new_password": NEW, "username": "rachel"},
                              content_type="application/json")
        self.assertEqual(r.status_code, 400)
        self.rachel.refresh_from_db()
        self.assertTrue(self.rachel.check_password("rachel-password"))

    @override_settings(CUTROOM_LOGIN_FAILURES_PER_USER=3)
    def test_guessing_the_current_password_is_throttled_like_signing_in(self):
        for _ in range(3):
            self.assertEqual(self.change(current="guess").status_code, 400)
        r = self.change()
        self.assertEqual(r.status_code, 429)
        self.assertIn("Retry-After", r)

    def test_an_anonymous_caller_is_refused(self):
        self.assertEqual(self.change(client=Client()).status_code, 401)


class PasswordResetTestCase(BaseTestCase):
    def reset(self, actor, target):
        client = Client()
        client.force_login(actor)
        return client.post(f"/api/auth/users/{target.pk}/password-reset/")

    def test_a_site_admin_resets_a_password_ending_its_sessions_and_tokens(self):
        root = get_user_model().objects.create_superuser("root", password="root-long-password")
        bobs = Client()
        bobs.login(username="bob", password="bob-password")
        ApiToken.objects.issue(self.bob)
        r = self.reset(root, self.bob)
        self.assertEqual(r.status_code, 200)
        self.assertEqual(r.json()["username"], "bob")
        self.bob.refresh_from_db()
        self.assertTrue(self.bob.check_password(r.json()["password"]))
        self.assertEqual(bobs.get("/api/me/").status_code, 401)
        self.assertFalse(ApiToken.objects.filter(user=self.bob).exists())

    def test_someone_who_is_not_a_site_admin_cannot_reset_a_password(self):
        r = self.reset(self.alice, self.bob)  # alice administers the project, not the site
        self.assertEqual(r.status_code, 403)
        self.assertIn("Only site admins", r.json()["detail"])
        self.bob.refresh_from_db()
        self.assertTrue(self.bob.check_password("bob-password"))
