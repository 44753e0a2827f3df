"""One kill of the Blender child from outside (the out-of-memory killer, an operator) does
not fail a good FBX: the read is tried once more in a fresh Blender (issue 48, item 11). A
file whose read Blender dies on twice fails, saying so; a SIGKILL failure is not permanent."""

import contextlib
import os
import signal
import threading
import time

import pytest

from motionlib.errors import CaptureError
from motionlib.io.blender import Blender, BlenderDied, blender_python
from motionlib.io.fbx import read_fbx_all
from tests.fbx.files import shared_fbx

FILE = "13_29_blender.fbx"  # Blender reads it for a second or more: time for a kill to land


@pytest.fixture
def blender():
    try:
        blender_python()
    except CaptureError as exc:
        pytest.skip(str(exc))
    b = Blender()
    yield b
    b.stop()


def read_with_kills(blender, kills):
    """Read FILE while ``kills`` Blenders in turn are SIGKILLed during it; (outcome, pids
    killed). Tried with other delays until every kill landed while a request was open."""
    for delay in (0.3, 0.1, 0.6, 1.0, 0.05):
        blender.start()
        outcome, killed = {}, []

        def read(outcome=outcome):
            try:
                outcome["takes"] = read_fbx_all(shared_fbx(FILE), blender=blender)
            except CaptureError as exc:
                outcome["error"] = exc

        reader = threading.Thread(target=read)
        reader.start()
        for _ in range(kills):
            time.sleep(delay)
            deadline = time.monotonic() + 60
            while (blender.pid is None or blender.pid in killed) and time.monotonic() < deadline:
                if not reader.is_alive():
                    break
                time.sleep(0.01)  # the fresh Blender is starting
            pid = blender.pid
            if pid is None or not reader.is_alive():
                break
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            killed.append(pid)
        reader.join(120)
        if len(killed) == kills and ("error" in outcome or blender.pid not in (None, *killed)):
            return outcome, killed
    raise AssertionError("the kills did not land while Blender was reading")


def test_one_kill_is_outlived_by_a_fresh_blender(blender):
    outcome, killed = read_with_kills(blender, kills=1)
    assert "error" not in outcome, outcome.get("error")
    assert outcome["takes"][0].n_frames > 0
    assert blender.pid not in killed


def test_a_second_kill_fails_the_file_saying_so_and_not_for_good(blender):
    outcome, _ = read_with_kills(blender, kills=2)
    error = outcome["error"]
    assert isinstance(error, BlenderDied)
    assert str(error).startswith(f"{FILE}: Blender was killed by signal SIGKILL"), str(error)
    assert "(it was tried 2 times, each in a fresh Blender)" in str(error)
    assert error.permanent is False


def test_a_blender_that_is_not_retried_fails_at_the_first_kill(tmp_path):
    try:
        blender_python()
    except CaptureError as exc:
        pytest.skip(str(exc))
    once = Blender(retry_deaths=0)
    try:
        outcome, _ = read_with_kills(once, kills=1)
    finally:
        once.stop()
    assert "tried" not in str(outcome["error"])
