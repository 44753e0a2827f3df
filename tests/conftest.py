"""Fixtures shared by every test folder. Keep this small; folder-specific fixtures live
in the folder's own conftest.py."""

import pytest

from motionlib.shared_data import data_dir
from tests.fbx.files import made_fbx  # noqa: F401  (the FBX files Blender writes for tests)

SHARED_DATA = data_dir()


@pytest.fixture(scope="session")
def shared_data():
    """The real CMU captures and labels beside the repository (skips if absent)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real CMU data not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session", autouse=True)
def _var_of_this_process(tmp_path_factory):
    """What a test writes outside its own folders (uploads, similar-clip indexes, the
    embedded broker's spool) goes to a folder of this test process, never to the
    checkout's var/: ``make pytest`` runs several test processes at once (pytest-xdist),
    and none may see another's files. Folder fixtures still override it per test."""
    from django.test import override_settings

    from cutroom.celery import app

    var = tmp_path_factory.mktemp("var")
    isolated = override_settings(MEDIA_ROOT=var / "media", SIMILAR_INDEX_DIR=var / "similar")
    isolated.enable()
    saved = app.conf.broker_transport_options
    if app.conf.broker_url.startswith("sqlite"):
        app.conf.broker_transport_options = {**saved, "path": str(var / "broker.sqlite3")}
    yield var
    app.conf.broker_transport_options = saved
    isolated.disable()


@pytest.fixture(scope="session")
def django_db_modify_db_settings(django_db_modify_db_settings_parallel_suffix, tmp_path_factory):
    """On SQLite, a test database in a file rather than in shared-cache memory, for every
    test of the session (the first test to ask for the database decides it for all, and
    with one process per core any test may come first).

    The browser tests' live server answers from its own threads while the test writes from
    this one; in shared-cache memory a second writer (or a writer meeting a reader) fails at once
    with "table is locked", whereas a file has the WAL and busy timeout the service is
    configured for, as in production.
    """
    from django.conf import settings

    db = settings.DATABASES["default"]
    if db["ENGINE"].endswith("sqlite3"):
        db.setdefault("TEST", {})["NAME"] = str(tmp_path_factory.mktemp("test-db") / "cutroom.sqlite3")
