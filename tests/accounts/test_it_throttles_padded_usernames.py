"""A locked username stays locked however much white space pads it (issue 48, item 2).

The throttle counted a typed username by its first 3,000 characters, while sign-in strips
the spaces and finds the account: 3,000 spaces (or U+3000 ideographic spaces) before the
name made every guess count for no one, and a locked account still signed in.
"""

from django.test import Client, override_settings

from tests.accounts.test_sign_in_throttle import LIMITS
from tests.segmentation.base import BaseTestCase

PADDINGS = (" " * 3000 + "bob", "\u3000" * 3000 + "bob", "\t\n" * 2000 + "bob",
            "bob" + " " * 3000, " " * 5000 + "bob" + "\u3000" * 5000)


@override_settings(**LIMITS)
class PaddedUsernameThrottleTestCase(BaseTestCase):
    def token(self, username, password="wrong", address="192.0.2.1"):
        return self.client.post("/api/auth/token/", {"username": username, "password": password},
                                format="json", REMOTE_ADDR=address)

    def login(self, username, password="wrong", address="192.0.2.1"):
        return Client().post("/login/", {"username": username, "password": password},
                             REMOTE_ADDR=address)

    def lock_bob(self):
        for _ in range(3):
            self.assertEqual(self.token("bob").status_code, 400)

    def test_a_locked_user_gets_no_token_with_a_padded_name(self):
        self.lock_bob()
        for k, padded in enumerate(PADDINGS):
            r = self.token(padded, "bob-password", address=f"198.51.100.{k}")
            self.assertEqual(r.status_code, 429, repr(padded[:8]))

    def test_a_locked_user_gets_no_session_with_a_padded_name(self):
        self.lock_bob()
        for k, padded in enumerate(PADDINGS):
            r = self.login(padded, "bob-password", address=f"198.51.100.{k}")
            self.assertEqual(r.status_code, 429, repr(padded[:8]))
            self.assertNotIn("sessionid", r.cookies)

    def test_padded_guesses_from_many_addresses_count_against_the_name(self):
        for k, padded in enumerate(PADDINGS[:3]):
            self.assertEqual(self.token(padded, address=f"203.0.113.{k}").status_code, 400)
        self.assertEqual(self.token("bob", "bob-password", address="192.0.2.9").status_code, 429)
        self.assertEqual(self.login("bob", "bob-password", address="192.0.2.9").status_code, 429)

    def test_a_padded_name_with_the_right_password_still_signs_in_when_not_locked(self):
        self.assertEqual(self.token(PADDINGS[0], "bob-password").status_code, 200)
