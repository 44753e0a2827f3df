"""``make up``'s bulk lane: requests about long takes are served by a niced web server of
their own, which still checks who may see what, and which up.py restarts when it dies while
the web server serves those requests itself; the niced children's nice values count."""

import json
import os
import re
import signal
import urllib.error
import urllib.request

import pytest

from tests.segmentation.test_command_up import gone, up_script, wait_until, wait_until_detected

pytestmark = pytest.mark.slow


def stat(pid):
    """(session id, nice value) of a process, from /proc."""
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return int(fields[3]), int(fields[16])


def get(server, path, token=None):
    """(status, X-Cutroom-Lane header, JSON body) of a GET."""
    headers = {"Authorization": f"Token {token}"} if token else {}
    request = urllib.request.Request(f"http://127.0.0.1:{server.port}{path}", headers=headers)
    try:
        with urllib.request.urlopen(request, timeout=20) as response:
            return response.status, response.headers.get("X-Cutroom-Lane"), json.loads(response.read())
    except urllib.error.HTTPError as error:
        return error.code, error.headers.get("X-Cutroom-Lane"), json.loads(error.read())


def test_the_bulk_lane_server_answers_checks_access_and_is_restarted_when_it_dies(up):
    # Every take counts as long here, so the demo's takes go to the bulk lane.
    server = up(env={"CUTROOM_LARGE_TAKE_FRAMES": "1"})
    output = server.wait_for("press Ctrl-C to stop")
    bulk = int(re.search(r"bulk lane server pid (\d+)", output)[1])
    token = server.api("/api/auth/token/", data={"username": "annotator",
                                                  "password": "cutroom-demo"})["token"]
    capture = wait_until_detected(server, token, 3)[0]["id"]
    review = f"/api/captures/{capture}/review/"

    status, lane, body = get(server, review, token)
    assert (status, lane) == (200, "bulk-server")
    assert body["cuts"]
    # The bulk lane's server refuses as the web server would.
    status, lane, body = get(server, review)
    assert (status, lane) == (401, "bulk-server")
    assert get(server, review, "not-a-token")[:2] == (401, "bulk-server")

    os.killpg(bulk, signal.SIGKILL)
    assert gone(bulk)
    # Meanwhile the web server serves the long take's requests itself.
    status, lane, body = get(server, review, token)
    assert status == 200 and body["cuts"]
    output = server.wait_for("bulk lane server restarted, pid")
    assert "the bulk lane server died (exit code -9)" in output
    wait_until(lambda: get(server, review, token)[1] == "bulk-server", timeout=60)
    # The niced children share up.py's session: the kernel shares the CPU equally between
    # sessions (autogroups), so in sessions of their own their nice values would not count.
    web, worker = server.pids()
    bulk = int(re.findall(r"bulk lane server restarted, pid (\d+)", server.output())[-1])
    session = stat(server.proc.pid)[0]
    constants = up_script()
    assert stat(bulk) == (session, constants.BULK_NICE)
    assert stat(worker) == (session, constants.WORKER_NICE)
    assert stat(web) == (session, 0)

    # Closing the terminal stops it all, as Ctrl-C does.
    server.proc.send_signal(signal.SIGHUP)
    assert server.proc.wait(60) == 0
    assert "SIGHUP received; stopping" in server.output()
    assert gone(web) and gone(worker) and gone(bulk)
