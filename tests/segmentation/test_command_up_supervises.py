"""``make up`` (scripts/up.py) keeps the service up without a person (issue 48, item 11):
the web server's death no longer ends the service, and a lost broker message does not get
a healthy worker restarted again and again: the waiting job is sent again first."""

import os
import signal
import subprocess
import sys
import urllib.error

import pytest

from tests.segmentation.test_command_up import REPO, wait_until
from tests.segmentation.test_command_up_recovery import FAST_WATCH, login

pytestmark = pytest.mark.slow


def answers(server, token):
    try:
        return server.api("/api/captures/", token)["count"] >= 1
    except (urllib.error.URLError, ConnectionError, TimeoutError):
        return False


def test_it_restarts_a_web_server_that_died(up):
    server = up()
    server.wait_for("press Ctrl-C to stop")
    token = login(server)
    web, _ = server.pids()
    os.killpg(web, signal.SIGKILL)  # gunicorn's master and its workers
    server.wait_for("web server restarted, pid", timeout=60)
    wait_until(lambda: answers(server, token), timeout=60)
    assert server.proc.poll() is None
    assert "the web server died" in server.output()


def a_job_whose_message_is_lost(server):
    """A detection run stored queued but never sent, as when the broker loses a message;
    its id."""
    code = ("from segmentation.models import Capture, DetectionRun; "
            "c = Capture.objects.filter(status='ready').order_by('pk').first(); "
            "print(DetectionRun.objects.create(capture=c, method='bone_angle', params={}).pk)")
    env = {k: v for k, v in os.environ.items()
           if k not in ("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT")}
    done = subprocess.run([sys.executable, "manage.py", "shell", "-c", code], cwd=REPO,
                          env={**env, "CUTROOM_VAR_DIR": str(server.var)}, capture_output=True,
                          text=True, check=True)
    return int(done.stdout.split()[-1])


def run_status(server, run_id):
    code = (f"from segmentation.models import DetectionRun; "
            f"print(DetectionRun.objects.get(pk={run_id}).status)")
    env = {k: v for k, v in os.environ.items()
           if k not in ("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT")}
    done = subprocess.run([sys.executable, "manage.py", "shell", "-c", code], cwd=REPO,
                          env={**env, "CUTROOM_VAR_DIR": str(server.var)}, capture_output=True,
                          text=True, check=True)
    return done.stdout.split()[-1]


def test_a_lost_message_is_sent_again_and_the_healthy_worker_kept(up):
    server = up(env=FAST_WATCH)
    server.wait_for("press Ctrl-C to stop")
    login(server)
    run_id = a_job_whose_message_is_lost(server)
    wait_until(lambda: run_status(server, run_id) == "ready", timeout=120)
    output = server.output()
    assert "its message may have been lost: 1 waiting job(s) sent again" in output
    assert "worker restarted" not in output
    assert "the worker is stuck" not in output
