"""FBX test files: the shared real ones, and the ones Blender writes for the tests."""

import subprocess
from pathlib import Path

import pytest

from motionlib.io.blender import blender_python
from motionlib.shared_data import data_dir

SHARED_DATA = data_dir()
SHARED_FBX = SHARED_DATA / "fbx"
MAKER = Path(__file__).with_name("make_files.py")


def shared_fbx(name: str) -> Path:
    path = SHARED_FBX / name
    if not path.is_file():
        pytest.skip(f"real FBX take {path} is not available (needs ../shared/data/fbx)")
    return path.resolve()


def shared_bvh_13_29() -> Path:
    path = SHARED_DATA / "cmu" / "bvh" / "13_29.bvh"
    if not path.is_file():
        pytest.skip(f"real CMU capture {path} is not available (needs ../shared/data)")
    return path.resolve()


@pytest.fixture(scope="session")
def made_fbx(tmp_path_factory):
    """Folder of the files ``make_files.py`` writes with Blender (see its docstring)."""
    shared_fbx("flair.fbx")
    out = tmp_path_factory.mktemp("fbx")
    done = subprocess.run([blender_python(), "-I", str(MAKER), str(SHARED_FBX), str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return out
