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
