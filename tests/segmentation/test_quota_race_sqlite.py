"""Quotas hold when requests come at once on the embedded default's SQLite file (threads
of one web process): simultaneous uploads by one person never pass
CUTROOM_UPLOADS_PER_HOUR, and one person's simultaneous detection runs in several projects
never pass CUTROOM_USER_ACTIVE_RUNS. Each request counts and inserts in one transaction
that holds the write lock from its start.

Runs in a child process on a database file of its own (the tests' in-memory database
is not shared between threads the way a file is)."""

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
UPLOAD_LIMIT, UPLOADS = 10, 30
RUN_LIMIT, STARTS = 3, 9

RACE = f"""
import django

django.setup()
from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile
from django.core.management import call_command
from django.test import override_settings
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Capture, DetectionRun
from tests.segmentation.race import at_once

override_settings(CUTROOM_UPLOADS_PER_HOUR={UPLOAD_LIMIT}, CUTROOM_USER_ACTIVE_RUNS={RUN_LIMIT},
                  CUTROOM_PROJECT_ACTIVE_RUNS=0).enable()
call_command("migrate", verbosity=0)
bob = get_user_model().objects.create_user("bob")
projects = [services.do_create_project(bob, f"Studio {{n}}") for n in range({STARTS})]

def client():
    c = APIClient()
    c.force_authenticate(bob)
    return c

def upload(n):
    c = client()
    body = {{"project": projects[n % len(projects)].pk,
             "file": SimpleUploadedFile(f"take{{n}}.bvh", f"HIERARCHY {{n}}".encode())}}
    return lambda: c.post("/api/captures/", body, format="multipart").status_code

codes = at_once([upload(n) for n in range({UPLOADS})])
print(sorted(codes), Capture.objects.filter(uploaded_by=bob).count(), flush=True)

ready = [Capture.objects.create(project=p, uploaded_by=bob, name="ready.bvh", format="bvh",
                                checksum=f"ready-{{p.pk}}", status="ready", fps=120.0,
                                n_frames=400, n_joints=2) for p in projects]

def start(capture):
    c = client()
    return lambda: c.post(f"/api/captures/{{capture.pk}}/runs/", {{"method": "bone_angle"}},
                          format="json").status_code

codes = at_once([start(capture) for capture in ready])
print(sorted(codes), DetectionRun.objects.filter(created_by=bob).count(), flush=True)
"""


def test_simultaneous_uploads_and_runs_of_one_person_never_pass_their_limits(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DATABASE_URL", "CELERY_BROKER_URL")}
    env.update(DJANGO_SETTINGS_MODULE="cutroom.settings", CUTROOM_VAR_DIR=str(tmp_path),
               CUTROOM_MEDIA_ROOT=str(tmp_path / "media"), PYTHONPATH=str(REPO))
    done = subprocess.run([sys.executable, "-c", RACE], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    uploads, runs = done.stdout.splitlines()
    assert uploads == f"{[201] * UPLOAD_LIMIT + [429] * (UPLOADS - UPLOAD_LIMIT)} {UPLOAD_LIMIT}"
    assert runs == f"{[202] * RUN_LIMIT + [429] * (STARTS - RUN_LIMIT)} {RUN_LIMIT}"
