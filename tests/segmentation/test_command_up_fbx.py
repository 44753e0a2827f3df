"""``make up`` converts FBX uploads on its own convert worker (Blender), then ingests them."""

import json
import re
import urllib.request
import uuid

import pytest

from tests.fbx.files import shared_fbx
from tests.segmentation.test_command_up import Up, free_port, wait_until

pytestmark = pytest.mark.slow


@pytest.fixture
def server(tmp_path):
    """One ``up.py`` on a fresh var folder, stopped (with its children) after the test."""
    started = Up(tmp_path / "var", free_port())
    yield started
    started.close()


def upload(server, token, path, project):
    boundary = uuid.uuid4().hex
    body = b"".join([
        f"--{boundary}\r\nContent-Disposition: form-data; name=\"project\"\r\n\r\n{project}\r\n"
        .encode(),
        f"--{boundary}\r\nContent-Disposition: form-data; name=\"file\"; filename=\"{path.name}\""
        "\r\nContent-Type: application/octet-stream\r\n\r\n".encode(),
        path.read_bytes(), f"\r\n--{boundary}--\r\n".encode(),
    ])
    request = urllib.request.Request(
        f"http://127.0.0.1:{server.port}/api/captures/", data=body,
        headers={"Content-Type": f"multipart/form-data; boundary={boundary}",
                 "Authorization": f"Token {token}"})
    with urllib.request.urlopen(request, timeout=30) as response:
        return json.loads(response.read())


def test_it_converts_an_fbx_upload_on_the_convert_worker(server):
    output = server.wait_for("FBX convert worker pid")
    assert re.search(r"FBX convert worker pid \d+ \(Blender\), log .*convert-worker.log", output)
    token = server.api("/api/auth/token/", data={"username": "admin",
                                                  "password": "cutroom-demo"})["token"]
    project = server.api("/api/projects/", token)[0]["id"]
    capture = upload(server, token, shared_fbx("flair.fbx"), project)
    assert capture["status"] == "queued"

    def detected():
        current = server.api(f"/api/captures/{capture['id']}/", token)
        run = current.get("latest_run")
        return current["status"] == "ready" and run and run["status"] == "ready"

    wait_until(detected)
    ready = server.api(f"/api/captures/{capture['id']}/", token)
    assert (ready["format"], ready["n_frames"], ready["fps"]) == ("fbx", 31, 30.0)
    log = (server.var / "log" / "convert-worker.log").read_text()
    assert "segmentation.tasks.convert" in log
    assert server.ctrl_c() == 0
