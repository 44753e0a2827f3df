"""Simultaneous wrong guesses for one username from many addresses, on PostgreSQL: only
CUTROOM_LOGIN_FAILURES_PER_USER of them have their password checked; the others are
refused with 429 (each attempt is counted before its password check, under a row lock)."""

import pytest
from django.contrib.auth import get_user_model
from django.test import Client, override_settings

from tests.segmentation.race import at_once

pytestmark = pytest.mark.integration
LIMIT, GUESSES = 10, 40


@override_settings(CUTROOM_LOGIN_FAILURES_PER_USER=LIMIT, CUTROOM_LOGIN_FAILURES_PER_ADDRESS=30)
def test_simultaneous_guesses_are_checked_only_up_to_the_limit(transactional_db, services_env):
    get_user_model().objects.create_user("bob", password="bob-password")

    def guess(i):
        client = Client(REMOTE_ADDR=f"198.51.100.{i}")
        return lambda: client.post("/api/auth/token/", {"username": "bob", "password": f"guess{i}"},
                                   content_type="application/json").status_code

    codes = sorted(at_once([guess(i) for i in range(GUESSES)]))
    assert codes == [400] * LIMIT + [429] * (GUESSES - LIMIT), codes
    r = Client(REMOTE_ADDR="203.0.113.1").post(
        "/api/auth/token/", {"username": " BOB", "password": "bob-password"},
        content_type="application/json")
    assert r.status_code == 429
