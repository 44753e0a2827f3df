"""Sign-in throttling on /api/auth/token/, /login/ and /admin/login/ (per username and
per client address, 429 with Retry-After, state in the database)."""

from datetime import timedelta

from django.contrib.auth import get_user_model
from django.test import Client, override_settings

from accounts.models import LoginFailure
from tests.segmentation.base import BaseTestCase

LIMITS = {
    "CUTROOM_LOGIN_WINDOW": 600,
    "CUTROOM_LOGIN_FAILURES_PER_USER": 3,
    "CUTROOM_LOGIN_FAILURES_PER_ADDRESS": 5,
}


@override_settings(**LIMITS)
class TokenEndpointThrottleTestCase(BaseTestCase):
    def token(self, username="bob", password="wrong", address="192.0.2.1", **extra):
        data = {"username": username, "password": password}
        return self.client.post("/api/auth/token/", data, format="json", REMOTE_ADDR=address, **extra)

    def fail(self, times, **kwargs):
        for _ in range(times):
            self.assertEqual(self.token(**kwargs).status_code, 400)

    def test_it_refuses_a_username_after_repeated_failures_with_429_and_retry_after(self):
        self.fail(3)
        r = self.token(password="bob-password")
        self.assertEqual(r.status_code, 429)
        self.assertTrue(0 < int(r["Retry-After"]) <= 600, r["Retry-After"])
        self.assertIn("Too many failed sign-ins", r.json()["detail"])

    def test_a_throttled_attempt_is_not_checked_nor_counted(self):
        self.fail(3)
        before = LoginFailure.objects.count()
        self.assertEqual(self.token(password="bob-password").status_code, 429)
        self.assertEqual(self.token().status_code, 429)
        self.assertEqual(LoginFailure.objects.count(), before)

    def test_it_throttles_a_username_whatever_address_the_attempts_come_from(self):
        for i in range(3):
            self.fail(1, address=f"198.51.100.{i}")
        self.assertEqual(self.token(password="bob-password", address="203.0.113.9").status_code, 429)

    def test_it_throttles_an_address_trying_many_usernames(self):
        for i in range(5):
            self.fail(1, username=f"guess{i}")
        self.assertEqual(self.token(password="bob-password").status_code, 429)
        self.assertEqual(self.token(password="bob-password", address="192.0.2.2").status_code, 200)

    def test_it_lets_the_username_in_again_once_its_failures_leave_the_window(self):
        self.fail(3)
        LoginFailure.objects.update(at=LoginFailure.objects.first().at - timedelta(seconds=601))
        self.assertEqual(self.token(password="bob-password").status_code, 200)

    def test_retry_after_counts_down_to_when_the_oldest_failure_leaves_the_window(self):
        self.fail(3)
        LoginFailure.objects.update(at=LoginFailure.objects.first().at - timedelta(seconds=500))
        self.assertTrue(95 <= int(self.token()["Retry-After"]) <= 100)

    def test_a_successful_sign_in_clears_the_usernames_failures(self):
        self.fail(2)
        self.assertEqual(self.token(password="bob-password").status_code, 200)
        self.fail(2)
        self.assertEqual(self.token(password="bob-password").status_code, 200)

    def test_the_username_is_counted_whatever_its_case(self):
        self.fail(2)
        self.fail(1, username="BOB")
        self.assertEqual(self.token(password="bob-password").status_code, 429)

    def test_it_keeps_no_username_in_clear(self):
        self.fail(1, username="hunter2-typed-in-the-wrong-field")
        keys = list(LoginFailure.objects.values_list("key", flat=True))
        self.assertEqual(len(keys), 2)
        self.assertFalse(any("hunter2" in key or "192.0.2.1" in key for key in keys))

    def test_it_ignores_x_forwarded_for_unless_told_a_proxy_sets_it(self):
        for i in range(5):
            self.fail(1, username=f"guess{i}", HTTP_X_FORWARDED_FOR=f"198.51.100.{i}")
        self.assertEqual(self.token(password="bob-password").status_code, 429)

    @override_settings(CUTROOM_TRUSTED_PROXIES=1)
    def test_behind_a_proxy_it_counts_the_address_the_proxy_saw(self):
        for i in range(5):
            self.fail(1, username=f"guess{i}", HTTP_X_FORWARDED_FOR=f"1.2.3.4, 198.51.100.{i}")
        self.assertEqual(self.token(password="bob-password").status_code, 200)
        for i in range(5):
            self.fail(1, username=f"again{i}", HTTP_X_FORWARDED_FOR="198.51.100.7")
        r = self.token(password="bob-password", HTTP_X_FORWARDED_FOR="198.51.100.7")
        self.assertEqual(r.status_code, 429)

    def test_it_counts_an_ipv6_client_by_its_64_network(self):
        for i in range(5):
            self.fail(1, username=f"guess{i}", address=f"2001:db8:1:2::{i + 1}")
        self.assertEqual(self.token(password="bob-password", address="2001:db8:1:2::99").status_code, 429)


@override_settings(**LIMITS)
class LoginPageThrottleTestCase(BaseTestCase):
    def sign_in(self, path="/login/", username="bob", password="wrong"):
        return Client().post(path, {"username": username, "password": password})

    def test_the_login_page_refuses_with_429_and_retry_after(self):
        for _ in range(3):
            self.assertContains(self.sign_in(), "Wrong username or password.")
        r = self.sign_in(password="bob-password")
        self.assertContains(r, "Too many failed sign-ins", status_code=429)
        self.assertTrue(0 < int(r["Retry-After"]) <= 600)

    def test_the_login_page_and_the_token_endpoint_share_one_count(self):
        for _ in range(2):
            self.sign_in()
        self.client.post("/api/auth/token/", {"username": "bob", "password": "x"}, format="json")
        self.assertEqual(self.sign_in(password="bob-password").status_code, 429)

    def test_the_admin_login_is_throttled_too(self):
        get_user_model().objects.create_superuser("root", password="root-password")
        for _ in range(3):
            self.assertEqual(self.sign_in("/admin/login/", "root").status_code, 200)
        r = self.sign_in("/admin/login/", "root", "root-password")
        self.assertEqual(r.status_code, 429)

    def test_a_successful_login_clears_the_usernames_failures(self):
        for _ in range(2):
            self.sign_in()
        self.assertEqual(self.sign_in(password="bob-password").status_code, 302)
        for _ in range(2):
            self.sign_in()
        self.assertEqual(self.sign_in(password="bob-password").status_code, 302)


@override_settings(**LIMITS)
class UsernameSpellingThrottleTestCase(BaseTestCase):
    def token(self, username, password="wrong"):
        return self.client.post("/api/auth/token/", {"username": username, "password": password},
                                format="json", REMOTE_ADDR="192.0.2.1")

    def test_a_locked_username_stays_locked_in_any_spelling(self):
        for _ in range(3):
            self.assertEqual(self.token("bob").status_code, 400)
        for spelling in (" bob", "bob ", "\tBOB\n", "\uff42\uff4f\uff42", "\u24d1ob"):
            self.assertEqual(self.token(spelling, "bob-password").status_code, 429, repr(spelling))

    def test_failures_in_other_spellings_count_against_one_name(self):
        for spelling in (" bob", "\uff42ob", "BOB"):
            self.assertEqual(self.token(spelling).status_code, 400)
        self.assertEqual(self.token("bob", "bob-password").status_code, 429)

    def test_the_login_page_counts_spellings_as_one_name(self):
        for spelling in ("bob ", "\uff42ob", "Bob"):
            Client().post("/login/", {"username": spelling, "password": "wrong"})
        r = Client().post("/login/", {"username": " bob", "password": "bob-password"})
        self.assertEqual(r.status_code, 429)

    def test_a_success_takes_back_only_its_own_advance_count_on_the_address(self):
        self.assertEqual(self.token("guess", "x").status_code, 400)
        self.assertEqual(self.token("bob", "bob-password").status_code, 200)
        self.assertEqual(LoginFailure.objects.count(), 2)  # guess's, by name and by address

    def test_a_huge_username_is_refused_like_any_wrong_one_and_counted(self):
        r = self.token("b" * 1_000_000)
        self.assertEqual(r.status_code, 400)
        self.assertEqual(LoginFailure.objects.count(), 2)
