"""Browser tests: Debian's Chromium driven by Playwright against the real Django app
(pytest-django's ``live_server``) with captures ingested and detected in-process.

The front end must be built (``make test`` runs ``npm run build`` first). Without
``frontend/dist`` the tests skip loudly, except under CI where that is a failure.
"""

import functools
import io
import os
import shutil
import threading
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DIST = REPO / "frontend" / "dist"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    # Software WebGL, so the three.js view renders (and shows in screenshots) headless.
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
]

# CI shares two cores among the web server, the browser and the tests: give the page
# more time than Playwright's default 5 s before calling it stuck.
EXPECT_TIMEOUT_MS = 15_000

# Playwright's sync API runs an event loop in this thread; the ORM calls the tests make
# between browser steps are still plain synchronous code.
os.environ.setdefault("DJANGO_ALLOW_ASYNC_UNSAFE", "true")


@pytest.fixture
def screenshots(tmp_path):
    """Where the tests save their screenshots: the README's ``docs/screenshots`` when
    ``CUTROOM_SCREENSHOTS=1`` (``make screenshots``), else a temporary folder, so a test
    run leaves the working tree as it found it."""
    if os.environ.get("CUTROOM_SCREENSHOTS") == "1":
        folder = REPO / "docs" / "screenshots"
        folder.mkdir(parents=True, exist_ok=True)
        return folder
    return tmp_path


def pytest_collection_modifyitems(items):
    for item in items:
        if "tests/e2e/" in str(item.fspath).replace(os.sep, "/"):
            item.add_marker(pytest.mark.e2e)


@pytest.fixture(scope="session")
def django_db_modify_db_settings(django_db_modify_db_settings_parallel_suffix, tmp_path_factory):
    """On SQLite, a test database in a file rather than in shared-cache memory.

    The live server answers from its own threads while the test writes from this one;
    in shared-cache memory a second writer (or a writer meeting a reader) fails at once
    with "table is locked", whereas a file has the WAL and busy timeout the service is
    configured for, as in production.
    """
    from django.conf import settings

    db = settings.DATABASES["default"]
    if db["ENGINE"].endswith("sqlite3"):
        db.setdefault("TEST", {})["NAME"] = str(tmp_path_factory.mktemp("e2e-db") / "cutroom.sqlite3")


@pytest.fixture(scope="session")
def built_frontend():
    if not (DIST / "index.html").is_file():
        message = (
            f"frontend not built: {DIST / 'index.html'} is missing. "
            "Run `make frontend` (or `cd frontend && npm ci && npm run build`)."
        )
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(message)
        pytest.skip(message)
    return DIST


@pytest.fixture(scope="session")
def browser(built_frontend):
    if not Path(CHROMIUM).exists():
        message = f"Chromium not found at {CHROMIUM} (make browser installs Debian's package)"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(message)
        pytest.skip(message)
    from playwright.sync_api import expect, sync_playwright

    expect.set_options(timeout=EXPECT_TIMEOUT_MS)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        yield browser
        browser.close()


@pytest.fixture(autouse=True)
def _isolated_storage(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"


@pytest.fixture(autouse=True)
def _in_memory_broker():
    """The upload and ingest services queue follow-up jobs on commit; these tests run
    those jobs in-process themselves, so queued messages go to an in-memory broker
    instead of the embedded spool folder under var/. Restored after each test, so
    the integration tests that follow still see their real broker."""
    from cutroom.celery import app

    saved = app.conf.broker_url, app.conf.broker_transport_options
    app.conf.broker_url, app.conf.broker_transport_options = "memory://", {}
    _forget_connections(app)
    yield
    app.conf.broker_url, app.conf.broker_transport_options = saved
    _forget_connections(app)


def _forget_connections(app):
    # Pools built from the old broker URL are dropped (not closed: kombu shares them),
    # so the next send builds new ones from the current configuration.
    app._pool = None
    app.amqp._producer_pool = None


@pytest.fixture
def studio(transactional_db):
    """alice administers "Studio A" (labels walk/punch/squat), ann and bob annotate,
    rachel reviews."""
    from django.contrib.auth import get_user_model

    from segmentation import services

    users = get_user_model().objects
    people = {name: users.create_user(name, password=f"{name}-password")
              for name in ("alice", "ann", "bob", "rachel")}
    project = services.do_create_project(people["alice"], "Studio A")
    services.do_set_member(project, "ann", "annotator")
    services.do_set_member(project, "bob", "annotator")
    services.do_set_member(project, "rachel", "reviewer")
    labels = [("walk", "#3b82f6", "1"), ("punch", "#ef4444", "2"), ("squat", "#22c55e", "3"),
              ("kick", "#f59e0b", "4"), ("jumping_jack", "#a855f7", "5")]
    for name, colour, key in labels:
        services.do_add_label(project, name, colour, key)
    return {"project": project, **people}


@functools.cache
def synthetic_bvh(seed, duration):
    """The BVH text of a seeded synthetic take. The same seed and duration give the same
    bytes, so each is generated once per test process (most tests ingest the same take)."""
    import motionlib

    take, _segments = motionlib.synth.generate(seed=seed, fps=120.0, duration=duration)
    text = io.StringIO()
    motionlib.write_bvh(take, text)
    return text.getvalue().encode()


@pytest.fixture
def ingested_capture(studio):
    """A 40-second synthetic take uploaded, ingested and detected by the service's own
    task functions, run here in-process as a worker would."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from tests.segmentation.base import ingested

    upload = SimpleUploadedFile("warmup_session.bvh", synthetic_bvh(seed=5, duration=40.0))
    capture = ingested(studio["project"], studio["alice"], upload)
    run = capture.latest_finished_run()
    assert run is not None and len(run.candidates) >= 4, "the detector proposed too few cuts"
    return capture


def login(page, base_url, username):
    page.goto(f"{base_url}/login/?next=/")
    page.fill("#id_username", username)
    page.fill("#id_password", f"{username}-password")
    page.click("button[type=submit]")
    page.wait_for_url(f"{base_url}/")


@pytest.fixture
def new_page(browser, live_server):
    """Open a fresh browser context (its own cookies) logged in as someone."""
    contexts = []

    def open_as(username, width=1440, height=900):
        context = browser.new_context(viewport={"width": width, "height": height})
        contexts.append(context)
        page = context.new_page()
        page.set_default_timeout(EXPECT_TIMEOUT_MS)
        page.errors = []
        page.on("pageerror", lambda exc: page.errors.append(str(exc)))
        login(page, live_server.url, username)
        return page

    yield open_as
    for context in contexts:
        context.close()
    _wait_for_requests_in_flight()


# How long a test's teardown waits for the live server to finish the requests its pages
# sent (a save still running when the test's last check passed).
REQUESTS_IN_FLIGHT_TIMEOUT_S = 15


def _wait_for_requests_in_flight():
    """Wait until the live server's request threads have ended.

    The database is emptied after each test; a request still being answered then (a save
    the page sent just before the test ended) holds a lock that makes the flush fail
    ("table is locked"), an error at teardown of a test that passed. Closing the browser
    contexts closes their connections, so each of the server's threads (one per
    connection, named after ``process_request_thread``) ends once its request is done.
    """
    deadline = time.monotonic() + REQUESTS_IN_FLIGHT_TIMEOUT_S
    for thread in threading.enumerate():
        if thread.name.endswith("(process_request_thread)"):
            thread.join(max(0.0, deadline - time.monotonic()))
