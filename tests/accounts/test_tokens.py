"""API tokens: they expire, and their owner (or a site admin) can revoke them."""

from datetime import timedelta

from django.contrib.auth import get_user_model
from django.test import Client, override_settings
from django.utils import timezone
from django.utils.dateparse import parse_datetime

from accounts.models import ApiToken, digest
from tests.segmentation.base import BaseTestCase


class TokensTestCase(BaseTestCase):
    def obtain(self, username="bob"):
        r = self.client.post("/api/auth/token/", {"username": username, "password": f"{username}-password"}, format="json")
        self.assertEqual(r.status_code, 200, r.content)
        return r.json()

    def call(self, key, method="get", path="/api/me/"):
        self.client.credentials(HTTP_AUTHORIZATION=f"Token {key}")
        try:
            return getattr(self.client, method)(path)
        finally:
            self.client.credentials()

    @override_settings(CUTROOM_TOKEN_DAYS=2)
    def test_a_token_expires_after_the_configured_days(self):
        body = self.obtain()
        expires = parse_datetime(body["expires_at"])
        self.assertAlmostEqual((expires - timezone.now()).total_seconds(), 2 * 86400, delta=60)
        self.assertEqual(self.call(body["token"]).status_code, 200)
        ApiToken.objects.update(expires_at=timezone.now() - timedelta(seconds=1))
        r = self.call(body["token"])
        self.assertEqual((r.status_code, r["WWW-Authenticate"]), (401, "Token"))
        self.assertIn("Token expired", r.json()["detail"])

    def test_a_token_is_revoked_by_the_request_that_carries_it(self):
        first, second = self.obtain()["token"], self.obtain()["token"]
        self.assertEqual(self.call(first, "delete", "/api/auth/token/").status_code, 204)
        self.assertEqual(self.call(first).status_code, 401)
        self.assertEqual(self.call(second).status_code, 200)

    def test_all_the_callers_tokens_are_revoked_at_once_and_nobody_elses(self):
        mine = [self.obtain()["token"] for _ in range(2)]
        theirs = self.obtain("rachel")["token"]
        r = self.call(mine[0], "delete", "/api/auth/tokens/")
        self.assertEqual((r.status_code, r.json()), (200, {"revoked": 2}))
        self.assertEqual([self.call(key).status_code for key in mine], [401, 401])
        self.assertEqual(self.call(theirs).status_code, 200)

    def test_a_session_user_revokes_their_tokens_by_id_but_not_someone_elses(self):
        key = self.obtain()["token"]
        self.obtain("rachel")
        rachels = ApiToken.objects.get(user=self.rachel)
        self.login(self.bob)
        listed = self.client.get("/api/auth/tokens/").json()
        self.assertEqual([(t["prefix"], t["current"]) for t in listed], [(key[:6], False)])
        self.assertNotIn(key, str(listed))
        self.assertEqual(self.client.delete(f"/api/auth/tokens/{rachels.pk}/").status_code, 404)
        self.assertEqual(self.client.delete(f"/api/auth/tokens/{listed[0]['id']}/").status_code, 204)
        self.client.force_authenticate(None)
        self.assertEqual(self.call(key).status_code, 401)
        self.assertTrue(ApiToken.objects.filter(pk=rachels.pk).exists())

    def test_revoking_the_current_token_by_session_says_how_to_revoke_them(self):
        self.login(self.bob)
        r = self.client.delete("/api/auth/token/")
        self.assertEqual(r.status_code, 400)
        self.assertIn("/api/auth/tokens/", r.json()["detail"])

    def test_an_anonymous_caller_cannot_list_or_revoke_tokens(self):
        self.obtain()
        self.assertEqual(self.client.get("/api/auth/tokens/").status_code, 401)
        self.assertEqual(self.client.delete("/api/auth/tokens/").status_code, 401)
        self.assertEqual(ApiToken.objects.count(), 1)

    def test_a_site_admin_revokes_a_token_in_the_admin(self):
        key = self.obtain()["token"]
        get_user_model().objects.create_superuser("root", password="root-password")
        admin = Client()
        admin.login(username="root", password="root-password")
        token = ApiToken.objects.get()
        r = admin.post(f"/admin/accounts/apitoken/{token.pk}/delete/", {"post": "yes"})
        self.assertEqual(r.status_code, 302)
        self.assertEqual(self.call(key).status_code, 401)

    def test_only_a_digest_of_the_key_is_stored(self):
        key = self.obtain()["token"]
        token = ApiToken.objects.get()
        self.assertEqual(token.digest, digest(key))
        self.assertNotIn(key, [str(v) for v in ApiToken.objects.values_list().get()])

    def test_a_stale_token_sent_along_does_not_stop_obtaining_a_new_one(self):
        self.client.credentials(HTTP_AUTHORIZATION="Token no-longer-valid")
        self.obtain()

    def test_a_user_keeps_at_most_twenty_live_tokens(self):
        keys = [self.obtain()["token"] for _ in range(21)]
        self.assertEqual(ApiToken.objects.filter(user=self.bob).count(), 20)
        self.assertEqual(self.call(keys[0]).status_code, 401)
        self.assertEqual(self.call(keys[-1]).status_code, 200)

    def test_a_deactivated_users_token_is_refused(self):
        key = self.obtain()["token"]
        get_user_model().objects.filter(pk=self.bob.pk).update(is_active=False)
        self.assertEqual(self.call(key).status_code, 401)

    def test_a_new_password_revokes_the_accounts_tokens_and_nobody_elses(self):
        key, theirs = self.obtain()["token"], self.obtain("rachel")["token"]
        self.bob.set_password("a-new-long-password")
        self.bob.save()
        self.assertEqual(self.call(key).status_code, 401)
        self.assertEqual(self.call(theirs).status_code, 200)

    def test_saving_an_account_without_a_new_password_keeps_its_tokens(self):
        key = self.obtain()["token"]
        self.bob.first_name = "Bob"
        self.bob.save()
        self.assertEqual(self.call(key).status_code, 200)
