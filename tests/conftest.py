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
