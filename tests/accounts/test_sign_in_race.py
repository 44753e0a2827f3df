"""Simultaneous wrong guesses for one username, each from its own address, on the
embedded default's SQLite file: only CUTROOM_LOGIN_FAILURES_PER_USER of them have their
password checked, the others are refused, because each attempt is counted before its
password is checked and under the username's row lock.

Runs in a child process on a database file of its own (the tests' in-memory database
is not shared between threads the way a file is)."""

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LIMIT, GUESSES = 10, 40

RACE = f"""
import django

django.setup()
from django.contrib.auth import get_user_model
from django.core.management import call_command
from django.test import Client, override_settings

from tests.segmentation.race import at_once

override_settings(PASSWORD_HASHERS=["django.contrib.auth.hashers.MD5PasswordHasher"],
                  CUTROOM_LOGIN_FAILURES_PER_USER={LIMIT}).enable()
call_command("migrate", verbosity=0)
get_user_model().objects.create_user("bob", password="bob-password")

def guess(i):
    client = Client(REMOTE_ADDR=f"198.51.100.{{i}}")
    return lambda: client.post("/api/auth/token/", {{"username": "bob", "password": f"guess{{i}}"}},
                               content_type="application/json").status_code

codes = at_once([guess(i) for i in range({GUESSES})])
print(sorted(codes))
"""


def test_simultaneous_guesses_from_many_addresses_are_checked_only_up_to_the_limit(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DATABASE_URL", "CELERY_BROKER_URL")}
    env.update(DJANGO_SETTINGS_MODULE="cutroom.settings", CUTROOM_VAR_DIR=str(tmp_path),
               CUTROOM_MEDIA_ROOT=str(tmp_path / "media"), PYTHONPATH=str(REPO))
    done = subprocess.run([sys.executable, "-c", RACE], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == str([400] * LIMIT + [429] * (GUESSES - LIMIT)), done.stdout
