"""The per-project limit on detection runs holds when starts come at once on the embedded
default's SQLite file (threads of one web process, as under gunicorn): each start counts
and inserts in one IMMEDIATE transaction, so the next one counts after it.

Run in a child process on a database file of its own: the tests' in-memory database
is not shared between threads the way a file is."""

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LIMIT, STARTS, ROUNDS = 2, 6, 10

RACE = f"""
import threading

import django

django.setup()
from django.conf import settings
from django.contrib.auth import get_user_model
from django.core.management import call_command
from django.db import connection

from segmentation import services
from segmentation.errors import TooManyRequests
from segmentation.models import Capture, DetectionRun

call_command("migrate", verbosity=0)
settings.CUTROOM_PROJECT_ACTIVE_RUNS = {LIMIT}
user = get_user_model().objects.create_user("alice")
project = services.do_create_project(user, "Studio A")
capture = Capture.objects.create(
    project=project, uploaded_by=user, name="take.bvh", format="bvh", checksum="take",
    status="ready", fps=120.0, n_frames=400, n_joints=2,
)

def start(codes, barrier):
    barrier.wait()
    try:
        services.do_start_run(Capture.objects.get(pk=capture.pk), user, "bone_angle", {{}})
        codes.append(202)
    except TooManyRequests:
        codes.append(429)
    finally:
        connection.close()

for _ in range({ROUNDS}):
    codes, barrier = [], threading.Barrier({STARTS})
    threads = [threading.Thread(target=start, args=(codes, barrier)) for _ in range({STARTS})]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(60)
    print(sorted(codes), DetectionRun.objects.filter(status="queued").count(), flush=True)
    DetectionRun.objects.update(status="ready")
"""


def test_concurrent_starts_never_pass_the_project_limit_on_sqlite(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DATABASE_URL", "CELERY_BROKER_URL")}
    env.update(DJANGO_SETTINGS_MODULE="cutroom.settings", CUTROOM_VAR_DIR=str(tmp_path),
               CUTROOM_MEDIA_ROOT=str(tmp_path / "media"))
    done = subprocess.run([sys.executable, "-c", RACE], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rounds = done.stdout.splitlines()
    assert len(rounds) == ROUNDS, done.stdout
    expected = f"{[202] * LIMIT + [429] * (STARTS - LIMIT)} {LIMIT}"
    assert rounds == [expected] * ROUNDS, done.stdout
