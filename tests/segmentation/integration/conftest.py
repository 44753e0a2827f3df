"""Real services for the integration tests: PostgreSQL, Redis and Celery worker processes.

The test process itself must run on PostgreSQL and Redis (``make pytest`` sets
``DATABASE_URL`` and ``CELERY_BROKER_URL``); workers are started as subprocesses pointing
at pytest-django's test database. If a service is missing the tests fail under CI
(``CI=true``) and skip loudly elsewhere.
"""

import contextlib
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path
from urllib.parse import urlparse

import pytest
from django.conf import settings
from django.contrib.auth import get_user_model
from django.db import connection
from rest_framework.test import APIClient

REPO = Path(__file__).resolve().parents[3]
CELERY = Path(sys.executable).with_name("celery")


def _unavailable(reason):
    message = f"integration services unavailable: {reason}"
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(message, pytrace=False)
    pytest.skip(message)


def _reachable(url, default_port):
    parts = urlparse(url)
    try:
        socket.create_connection((parts.hostname, parts.port or default_port), timeout=2).close()
    except OSError as exc:
        return f"{parts.hostname}:{parts.port or default_port} ({exc})"
    return None


@pytest.fixture(scope="session")
def services_env():
    if connection.vendor != "postgresql":
        _unavailable(
            "the database is not PostgreSQL; run with "
            "DATABASE_URL=postgres://postgres@127.0.0.1:5432/test (make pytest does)"
        )
    db = connection.settings_dict
    problem = _reachable(f"postgres://{db['HOST'] or '127.0.0.1'}:{db['PORT'] or 5432}", 5432)
    if problem:
        _unavailable(f"PostgreSQL not reachable at {problem}")
    if not settings.CELERY_BROKER_URL.startswith("redis"):
        _unavailable(
            "the broker is not Redis; run with CELERY_BROKER_URL=redis://127.0.0.1:6379/15"
        )
    problem = _reachable(settings.CELERY_BROKER_URL, 6379)
    if problem:
        _unavailable(f"Redis not reachable at {problem}")


@pytest.fixture(scope="session")
def django_db_setup(services_env, django_db_setup):
    """Check the services before pytest-django tries to create the test database."""


def new_queue():
    """A queue of its own, so parallel test runs sharing one Redis never mix jobs."""
    return f"cutroom-test-{uuid.uuid4().hex[:8]}"


@pytest.fixture(scope="session")
def shared_media(tmp_path_factory):
    return tmp_path_factory.mktemp("integration-media")


@pytest.fixture(autouse=True)
def media_root(settings, shared_media):
    """Override the per-test folder: workers and the test process must share one."""
    settings.MEDIA_ROOT = shared_media
    return shared_media


@contextlib.contextmanager
def sending_to(queue):
    """Jobs enqueued by the test process go to ``queue``."""
    from cutroom.celery import app

    previous = app.conf.task_default_queue
    app.conf.task_default_queue = queue
    try:
        yield
    finally:
        app.conf.task_default_queue = previous


class Workers:
    """Celery worker subprocesses on the test database; all stopped at teardown."""

    def __init__(self, queue, media, logs, claim_timeout):
        db = connection.settings_dict
        self.env = {
            **os.environ,
            "DJANGO_SETTINGS_MODULE": "cutroom.settings",
            "DATABASE_URL": f"postgres://{db['USER']}@{db['HOST']}:{db['PORT'] or 5432}/{db['NAME']}",
            "CELERY_BROKER_URL": settings.CELERY_BROKER_URL,
            "CELERY_QUEUE": queue,
            "CUTROOM_MEDIA_ROOT": str(media),
            "CUTROOM_SIMILAR_INDEX_DIR": str(media / "similar"),
            "CUTROOM_CLAIM_TIMEOUT": str(claim_timeout),
        }
        self.queue, self.logs, self.procs = queue, logs, []

    def start(self, name=None, options=None):
        """A worker of one pool process on this queue, or with ``options`` (its queue, its
        concurrency) instead."""
        name = name or f"w{len(self.procs)}-{uuid.uuid4().hex[:6]}"
        log = self.logs / f"{name}.log"
        options = options or ["-c", "1", "-Q", self.queue]
        proc = subprocess.Popen(
            [str(CELERY), "-A", "cutroom", "worker", "--pool=prefork", *options,
             "-n", f"{name}@%h", "--without-mingle", "--without-gossip", "-l", "INFO"],
            cwd=REPO, env=self.env, stdout=log.open("w"), stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        proc.log = log
        self.procs.append(proc)
        self._wait_ready(proc)
        return proc

    def _wait_ready(self, proc, timeout=30):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if " ready." in proc.log.read_text():
                return
            if proc.poll() is not None:
                raise RuntimeError(f"worker exited early:\n{proc.log.read_text()}")
            time.sleep(0.1)
        raise RuntimeError(f"worker not ready after {timeout}s:\n{proc.log.read_text()}")

    def children(self, proc):
        out = subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True, text=True)
        return [int(pid) for pid in out.stdout.split()]

    def kill(self, proc):
        """SIGKILL the whole worker (main process and pool children)."""
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(10)

    def stop_all(self):
        for proc in self.procs:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGTERM)
        for proc in self.procs:
            try:
                proc.wait(15)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait(5)


@pytest.fixture(scope="session")
def worker_pair(services_env, django_db_setup, shared_media, tmp_path_factory):
    """Two workers kept for the whole session (for tests that do not kill them)."""
    # A long claim timeout: a slow ingest on a busy machine must not look abandoned,
    # or the duplicate deliveries of the same job would rightly take it over.
    pool = Workers(new_queue(), shared_media, tmp_path_factory.mktemp("worker-logs"), 300)
    pool.start()
    pool.start()
    yield pool
    pool.stop_all()


@pytest.fixture
def running_workers(worker_pair, transactional_db):
    with sending_to(worker_pair.queue):
        yield worker_pair


@pytest.fixture
def workers(services_env, shared_media, tmp_path, transactional_db):
    """Workers of this test only, on a queue of their own; the test may kill them."""
    pool = Workers(new_queue(), shared_media, tmp_path, claim_timeout=3)
    with sending_to(pool.queue):
        yield pool
    pool.stop_all()


def wait_for(predicate, timeout=60, interval=0.05, what="condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(interval)
    raise AssertionError(f"timed out after {timeout}s waiting for {what}")


@pytest.fixture
def two_admins(transactional_db, services_env):
    """A project with two admins, alice (who created it) and rachel: (project, alice, rachel)."""
    from segmentation import services
    from segmentation.models import Membership

    users = get_user_model().objects
    alice = users.create_user("alice", password="alice-password")
    rachel = users.create_user("rachel", password="rachel-password")
    project = services.do_create_project(alice, "Studio A")
    Membership.objects.create(project=project, user=rachel, role="admin")
    return project, alice, rachel


def at_once(calls, timeout=30):
    """Make the API requests of ``calls`` — (user, request) pairs, where ``request(client)``
    sends one request with a client signed in as that user — each from its own thread,
    released together; their responses, sorted by status code."""
    start = threading.Barrier(len(calls))
    responses = []

    def one(user, request):
        client = APIClient()
        client.force_authenticate(user)
        try:
            start.wait()
            responses.append(request(client))
        finally:
            connection.close()

    threads = [threading.Thread(target=one, args=call) for call in calls]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout)
    return sorted(responses, key=lambda response: response.status_code)
