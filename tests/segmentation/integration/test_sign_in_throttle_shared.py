"""Sign-in failures counted by one process throttle the next attempt in another: the
count lives in the database every web process shares, not in a process's memory."""

import os
import subprocess
import sys

import pytest
from django.contrib.auth import get_user_model
from django.db import connection
from django.test import override_settings
from rest_framework.test import APIClient

pytestmark = pytest.mark.integration

ANOTHER_PROCESS = """
import django
django.setup()
from django.test import Client
client = Client(REMOTE_ADDR="192.0.2.50")
for _ in range(3):
    r = client.post("/api/auth/token/", {"username": "bob", "password": "wrong"},
                    content_type="application/json")
    print(r.status_code)
"""


@override_settings(CUTROOM_LOGIN_FAILURES_PER_USER=3)
def test_failures_counted_in_another_process_throttle_this_one(transactional_db, services_env):
    get_user_model().objects.create_user("bob", password="bob-password")
    db = connection.settings_dict
    env = {
        **os.environ,
        "DJANGO_SETTINGS_MODULE": "cutroom.settings",
        "DATABASE_URL": f"postgres://{db['USER']}@{db['HOST']}:{db['PORT'] or 5432}/{db['NAME']}",
        "CUTROOM_LOGIN_FAILURES_PER_USER": "3",
    }
    out = subprocess.run([sys.executable, "-c", ANOTHER_PROCESS], env=env, capture_output=True,
                         text=True, timeout=120, check=True).stdout.split()
    assert out == ["400", "400", "400"]
    r = APIClient().post("/api/auth/token/", {"username": "bob", "password": "bob-password"},
                         format="json", REMOTE_ADDR="198.51.100.7")
    assert r.status_code == 429 and int(r["Retry-After"]) > 0
