"""``make up`` recovers its worker without a person: a pool that hangs after one of its
processes was killed, a worker that keeps dying; the web server serves throughout."""

import io
import json
import os
import signal
import urllib.request
import uuid
from pathlib import Path

import pytest

from tests.segmentation.base import synthetic_bvh
from tests.segmentation.test_command_up import up_script, wait_until, wait_until_detected

pytestmark = pytest.mark.slow

FAST_WATCH = {"CUTROOM_STALL_SECONDS": "10", "CUTROOM_SWEEP_SECONDS": "2"}


def test_it_restarts_at_once_up_to_the_rate_limit_then_waits_longer_each_time():
    script = up_script()
    now = [0.0]
    restarts = script.Restarts(clock=lambda: now[0])
    pauses = []
    for _ in range(script.RESTARTS_IN_WINDOW + 3):
        pauses.append(restarts.pause())
        now[0] += 1
    assert pauses == [0.0] * script.RESTARTS_IN_WINDOW + [5.0, 10.0, 20.0]
    now[0] += script.RESTART_WINDOW
    assert restarts.pause() == 0.0  # deaths long ago no longer count


def login(server):
    return server.api("/api/auth/token/", data={"username": "annotator",
                                                "password": "cutroom-demo"})["token"]


def upload(server, token, seed):
    boundary = uuid.uuid4().hex
    body = io.BytesIO()
    body.write(f'--{boundary}\r\nContent-Disposition: form-data; name="project"\r\n\r\n1\r\n'
               f'--{boundary}\r\nContent-Disposition: form-data; name="file"; '
               f'filename="take-{seed}.bvh"\r\n\r\n'.encode())
    body.write(synthetic_bvh(seed=seed, duration=20.0))
    body.write(f"\r\n--{boundary}--\r\n".encode())
    request = urllib.request.Request(
        f"http://127.0.0.1:{server.port}/api/captures/", data=body.getvalue(),
        headers={"Content-Type": f"multipart/form-data; boundary={boundary}",
                 "Authorization": f"Token {token}"},
    )
    with urllib.request.urlopen(request, timeout=30) as response:
        return json.loads(response.read())["id"]


def detected(server, token, capture_id):
    capture = server.api(f"/api/captures/{capture_id}/", token)
    run = capture["latest_run"] or {}
    return capture["status"] == "ready" and run.get("status") == "ready"


def pool_processes(worker_pid):
    children = Path(f"/proc/{worker_pid}/task/{worker_pid}/children").read_text().split()
    return [int(pid) for pid in children]


def reading_the_job_pipe(worker_pid):
    """The idle pool process blocked reading the pool's job pipe: it holds the pipe's
    lock, so killing it leaves the other pool processes waiting on that lock forever."""
    for pid in pool_processes(worker_pid):
        if "pipe_read" in Path(f"/proc/{pid}/wchan").read_text():
            return pid
    return None


def test_it_restarts_a_worker_whose_pool_hangs_after_an_idle_process_was_killed(up):
    server = up("--concurrency", "2", env=FAST_WATCH)
    server.wait_for("press Ctrl-C to stop")
    token = login(server)
    wait_until_detected(server, token, 3)
    _, worker = server.pids()
    wait_until(lambda: reading_the_job_pipe(worker), timeout=30)
    os.kill(reading_the_job_pipe(worker), signal.SIGKILL)

    capture_id = upload(server, token, seed=21)

    wait_until(lambda: detected(server, token, capture_id), timeout=120)
    output = server.output()
    assert "the worker is stuck: a job has waited" in output
    assert "worker restarted, pid" in output


def test_it_keeps_serving_while_a_worker_that_keeps_dying_is_restarted(up):
    server = up()
    server.wait_for("press Ctrl-C to stop")
    token = login(server)
    for deaths in range(1, 5):
        os.killpg(current_worker(server), signal.SIGKILL)
        wait_until(lambda n=deaths: server.output().count("worker restarted, pid") == n, timeout=60)
        assert server.api("/api/captures/", token)["count"] == 3  # the web server answers
    assert server.proc.poll() is None
    capture_id = upload(server, token, seed=22)
    wait_until(lambda: detected(server, token, capture_id), timeout=120)


def current_worker(server):
    output = server.output()
    restarted = output.rsplit("worker restarted, pid ", 1)
    if len(restarted) == 2:
        return int(restarted[1].split()[0])
    return server.pids()[1]
