"""What Blender says about a file reaches its uploader without server paths, and without
anything of the files Blender read before (issue 48, item 6).

The Blender process stays up between files (other projects' uploads too), and its log
tail went into the message of the next file it died on: another project's upload with its
server path, and ``.venv-bpy/.../bpy/ops.py:109``.
"""

import contextlib
import os
import shutil
import signal
import threading
import time

import pytest

from motionlib.errors import CaptureError
from motionlib.io.blender import Blender, blender_python, scrub
from motionlib.io.fbx import read_fbx_all
from tests.fbx.files import shared_fbx


@pytest.fixture
def blender():
    try:
        blender_python()
    except CaptureError as exc:
        pytest.skip(str(exc))
    b = Blender(retry_deaths=0)  # a kill's message as it is told, not tried again
    yield b
    b.stop()


def killed_while_reading(blender, path):
    """The error of reading ``path`` while Blender is killed from outside.

    The kill must land while Blender reads: on a busy machine a read may finish before
    it, or the kill may come before the request reached Blender (which is then started
    afresh and reads the file). Each such attempt is tried again with another delay."""
    for delay in (0.3, 0.1, 0.6, 1.0, 0.05, 2.0):
        outcome = {}

        def read(outcome=outcome):
            try:
                read_fbx_all(path, blender=blender)
            except CaptureError as exc:
                outcome["error"] = str(exc)

        blender.start()
        pid = blender.pid
        reader = threading.Thread(target=read)
        reader.start()
        time.sleep(delay)  # the request is on its way; Blender is reading the file
        with contextlib.suppress(ProcessLookupError):  # it ended on its own meanwhile
            os.kill(pid, signal.SIGKILL)
        reader.join(60)
        if "error" in outcome:
            return outcome["error"]
    raise AssertionError("no kill landed while Blender was reading")


def test_a_crash_names_no_earlier_file_and_no_path(blender, tmp_path):
    secret = tmp_path / "captures" / "2" / "SECRET-p2-client-contract-1.fbx"
    secret.parent.mkdir(parents=True)
    secret.write_bytes(shared_fbx("flair.fbx").read_bytes()[:20000])  # truncated: fails
    with pytest.raises(CaptureError):
        read_fbx_all(secret, blender=blender)
    mine = tmp_path / "captures" / "7" / "mine.fbx"
    mine.parent.mkdir(parents=True)
    shutil.copy(shared_fbx("breakdance_1990.fbx"), mine)

    error = killed_while_reading(blender, mine)

    assert error.startswith("mine.fbx: Blender was killed by signal SIGKILL"), error
    assert "SECRET" not in error and "/" not in error, error


def test_an_importer_error_names_the_file_by_its_name_only(blender, tmp_path):
    broken = tmp_path / "deep" / "folder" / "broken.fbx"
    broken.parent.mkdir(parents=True)
    broken.write_bytes(shared_fbx("flair.fbx").read_bytes()[:20000])
    with pytest.raises(CaptureError) as caught:
        read_fbx_all(broken, blender=blender)
    assert "broken.fbx" in str(caught.value) and str(tmp_path) not in str(caught.value)


def test_scrub_keeps_the_files_name_and_drops_every_other_path():
    text = ("Error: Couldn't open file '/srv/media/captures/7/mine.fbx' | File "
            "\"/srv/.venv-bpy/lib/python3.11/site-packages/bpy/ops.py\", line 109, in __call__"
            " | saw /srv/media/captures/2/SECRET-p2 client.fbx and .venv-bpy/x/y.py:3")
    out = scrub(text, "/srv/media/captures/7/mine.fbx")
    assert "'mine.fbx'" in out
    assert "SECRET" not in out and "/" not in out and "venv" not in out, out
