"""``scripts/up.py`` (``make up``) as a person runs it: a real gunicorn and a real Celery
worker on the embedded default (SQLite + SQLite broker in a fresh var folder)."""

import importlib.util
import json
import os
import re
import signal
import socket
import sqlite3
import subprocess
import sys
import time
import urllib.request
from datetime import UTC, datetime
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
UP = REPO / "scripts" / "up.py"

pytestmark = pytest.mark.slow


def up_script():
    """``scripts/up.py`` as a module (its constants, its classes), without running it."""
    spec = importlib.util.spec_from_file_location("up_script", UP)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def patience(timeout):
    """``timeout`` stretched by how busy the machine is: these waits bound how long a test
    waits for processes that share the CPU with whatever else runs (a whole test suite,
    other builds), so a loaded machine gets longer before a wait counts as a failure; a
    passing test returns as soon as its condition holds."""
    busy = os.getloadavg()[0] / (os.cpu_count() or 1)
    return timeout * min(4.0, max(1.0, busy))


def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class Up:
    """One ``up.py`` process with its output in a file."""

    def __init__(self, var, port, *args, env=None):
        env = {**{k: v for k, v in os.environ.items()
                  if k not in ("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT")},
               **(env or {})}
        env["CUTROOM_VAR_DIR"] = str(var)
        self.var, self.port, self.out = var, port, var.parent / f"up-{port}.out"
        self.proc = subprocess.Popen(
            [sys.executable, str(UP), "--port", str(port), "--concurrency", "1",
             "--no-shared-data", *args],
            cwd=REPO, env=env, stdout=self.out.open("w"), stderr=subprocess.STDOUT,
            start_new_session=True,
        )

    def output(self):
        return self.out.read_text()

    def wait_for(self, text, timeout=120):
        timeout = patience(timeout)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in self.output():
                return self.output()
            if self.proc.poll() is not None:
                raise AssertionError(f"up.py exited ({self.proc.returncode}):\n{self.output()}")
            time.sleep(0.2)
        raise AssertionError(f"{text!r} not printed after {timeout}s:\n{self.output()}")

    def pids(self):
        match = re.search(r"web server pid (\d+), worker pid (\d+)", self.output())
        return int(match[1]), int(match[2])

    def ctrl_c(self, timeout=60):
        self.proc.send_signal(signal.SIGINT)
        return self.proc.wait(timeout)

    def close(self):
        """After a failed test: up.py stops its children on SIGTERM; force it if not."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(60)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(10)
        # Children run in their own process groups; none may outlive the test.
        for pid in map(int, re.findall(r"pid (\d+)", self.output())):
            try:
                os.killpg(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass

    def api(self, path, token=None, data=None):
        request = urllib.request.Request(
            f"http://127.0.0.1:{self.port}{path}",
            data=None if data is None else json.dumps(data).encode(),
            headers={"Content-Type": "application/json",
                     **({"Authorization": f"Token {token}"} if token else {})},
        )
        with urllib.request.urlopen(request, timeout=10) as response:
            return json.loads(response.read())


def gone(pgid, timeout=15):
    """True once no live process is left in process group ``pgid`` (zombies don't count)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if not any(_live_in_group(stat, pgid) for stat in Path("/proc").glob("[0-9]*/stat")):
            return True
        time.sleep(0.1)
    return False


def _live_in_group(stat, pgid):
    try:
        # Fields after the command name: state ppid pgrp ...
        fields = stat.read_text().rsplit(")", 1)[1].split()
    except OSError:
        return False
    return int(fields[2]) == pgid and fields[0] != "Z"


def test_it_serves_the_demo_survives_a_dead_worker_stops_on_ctrl_c_and_runs_again(up):
    # One test walks the whole life cycle: each start of up.py costs seconds.
    server = up()
    output = server.wait_for("press Ctrl-C to stop")
    assert f"Cutroom is running at http://127.0.0.1:{server.port}/" in output
    assert "log in as annotator / cutroom-demo" in output
    token = server.api("/api/auth/token/", data={"username": "annotator",
                                                  "password": "cutroom-demo"})["token"]
    captures = wait_until_detected(server, token, 3)
    assert all(c["latest_run"]["n_candidates"] > 0 for c in captures)

    # The worker dies holding a job: the row says processing, the broker has no message.
    held = captures[0]["id"]
    mark_processing(server.var / "cutroom.sqlite3", held)
    web, worker = server.pids()
    os.killpg(worker, signal.SIGKILL)
    output = server.wait_for("restarting the worker")
    assert "the worker died (exit code -9); end of" in output
    assert "worker.log" in output
    assert "the dead worker's jobs: 1 stale job(s) requeued" in output
    output = server.wait_for("worker restarted, pid")
    new_worker = int(re.search(r"worker restarted, pid (\d+)", output)[1])
    assert new_worker != worker and gone(worker)
    # The restarted worker ingests the held capture again and detects on it again.
    wait_until(lambda: len(server.api(f"/api/captures/{held}/runs/", token)) == 2
               and server.api(f"/api/captures/{held}/", token)["status"] == "ready")

    assert server.ctrl_c() == 0
    assert "SIGINT received; stopping" in server.output()
    assert gone(web) and gone(new_worker)

    # Running it again on the same folder adds nothing twice.
    again = up()
    output = again.wait_for("press Ctrl-C to stop")
    assert "added" not in output
    assert output.count("present  synth-") == 3
    assert again.api("/api/captures/", token)["count"] == 3
    assert again.ctrl_c() == 0


def test_a_stop_signal_is_noted_where_it_lands_and_raised_at_the_next_nap():
    # Raised from the handler, a Ctrl-C landing inside Django's first import (just after
    # the banner) became a RuntimeError and up.py exited 1 with a traceback.
    script = up_script()
    script.on_signal(signal.SIGINT, None)  # returns wherever it lands
    script.on_signal(signal.SIGTERM, None)
    assert script.STOPPING == ["SIGINT", "SIGTERM"]
    with pytest.raises(script.Stop, match="SIGINT"):
        script.nap(60)  # at once, not after the minute


def test_a_nap_without_a_stop_signal_sleeps_its_time():
    script = up_script()
    started = time.monotonic()
    script.nap(0.25)
    assert time.monotonic() - started >= 0.25


def mark_processing(database, capture_id):
    """What a worker's claim leaves on a capture row (written straight to the SQLite file)."""
    with sqlite3.connect(database, timeout=20) as db:
        db.execute(
            "UPDATE segmentation_capture SET status = 'processing', claim_token = 'dead-worker', "
            "claimed_at = ?, attempts = attempts + 1 WHERE id = ?",
            (datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S.%f"), capture_id),
        )


def wait_until(predicate, timeout=120):
    timeout = patience(timeout)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.5)
    raise AssertionError(f"condition not met after {timeout}s")


def wait_until_detected(server, token, count, timeout=120):
    timeout = patience(timeout)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        captures = server.api("/api/captures/", token)["results"]
        runs = [c["latest_run"] for c in captures]
        if len(captures) == count and all(r and r["status"] == "ready" for r in runs):
            return captures
        time.sleep(0.5)
    raise AssertionError(f"captures not detected after {timeout}s: {captures}")


def test_it_refuses_a_port_in_use_and_says_what_to_do(up, tmp_path):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        server = Up(tmp_path / "var", port)
        code = server.proc.wait(60)
    assert code == 2
    assert f"cannot listen on 127.0.0.1:{port}" in server.output()
    assert f"make up PORT={port + 1}" in server.output()
