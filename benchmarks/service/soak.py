"""Soak: the embedded default (`make up`) under mixed load while its worker is killed.

Runs ``scripts/up.py`` as a person does (SQLite, the SQLite broker, a real Celery
worker with 2 pool processes, gunicorn) in a temporary folder with the service's
default settings, then for ``--minutes`` minutes, over HTTP:

- uploads a new synthetic take (20-90 s, 120 fps) every ``--upload-every`` seconds;
- reviews: as the annotator, opens a ready capture's review and moves, deletes,
  inserts and labels cuts, and sometimes submits it, every few seconds;
- every ``--kill-every`` seconds kills part of the worker, in turn: a pool process
  while it runs a job, the idle pool process that holds the pool's job-pipe lock (the
  kill that used to hang the pool), and the whole worker (main and pool processes).

Then it stops loading and waits (up to ``--drain`` s) for every job to finish, and
prints: broker messages sent / processed (acknowledged) / still waiting / lost (sent,
yet neither processed nor waiting), jobs stuck (captures or runs not ready or failed
after the drain), jobs failed, HTTP 5xx responses and refused connections (the web
server down), and what up.py did (restarts, stalls found).

    .venv/bin/python -m benchmarks soak -- [--minutes 30] [--port 18600]

Target: lost, stuck and 5xx all 0.
"""

import argparse
import io
import json
import os
import random
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
import uuid
from collections import Counter
from pathlib import Path

from benchmarks.harness import REPO
from benchmarks.harness.service import up_script


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--port", type=int, default=0, help="0: a free port")
    parser.add_argument("--upload-every", type=float, default=20.0, help="seconds")
    parser.add_argument("--kill-every", type=float, default=120.0, help="seconds")
    parser.add_argument("--drain", type=float, default=300.0, help="seconds, at the end")
    parser.add_argument("--seed", type=int, default=0)
    return parser.parse_args()


def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class Client:
    """HTTP to the service, counting every status (and refused connections)."""

    def __init__(self, port):
        self.base, self.token, self.statuses = f"http://127.0.0.1:{port}", None, Counter()

    def call(self, method, path, body=None, content_type="application/json"):
        if isinstance(body, dict):
            body = json.dumps(body).encode()
        headers = {"Content-Type": content_type}
        if self.token:
            headers["Authorization"] = f"Token {self.token}"
        request = urllib.request.Request(self.base + path, body, headers, method=method)
        try:
            with urllib.request.urlopen(request, timeout=120) as response:
                self.statuses[response.status] += 1
                return response.status, json.loads(response.read() or b"null")
        except urllib.error.HTTPError as error:
            self.statuses[error.code] += 1
            return error.code, None
        except (urllib.error.URLError, OSError) as error:
            self.statuses[f"no answer ({type(getattr(error, 'reason', error)).__name__})"] += 1
            return None, None

    def login(self, username):
        _, body = self.call("POST", "/api/auth/token/",
                            {"username": username, "password": "cutroom-demo"})
        self.token = body["token"]

    def upload(self, name, content):
        boundary = uuid.uuid4().hex
        body = (f'--{boundary}\r\nContent-Disposition: form-data; name="project"\r\n\r\n1\r\n'
                f'--{boundary}\r\nContent-Disposition: form-data; name="file"; '
                f'filename="{name}"\r\n\r\n').encode() + content + f"\r\n--{boundary}--\r\n".encode()
        return self.call("POST", "/api/captures/", body,
                         f"multipart/form-data; boundary={boundary}")


def synthetic_take(seed, duration):
    from motionlib import synth, write_bvh

    take, _ = synth.generate(seed=seed, fps=120.0, duration=duration)
    text = io.StringIO()
    write_bvh(take, text)
    return text.getvalue().encode()


def start_up(var, port):
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("CUTROOM_", "CELERY_")) and k != "DATABASE_URL"}
    env["CUTROOM_VAR_DIR"] = str(var)
    out = var.parent / "up.out"
    proc = subprocess.Popen(
        [sys.executable, str(REPO / "scripts" / "up.py"), "--port", str(port),
         "--no-shared-data"],
        cwd=REPO, env=env, stdout=out.open("w"), stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    deadline = time.monotonic() + 300
    while "press Ctrl-C to stop" not in out.read_text():
        if proc.poll() is not None or time.monotonic() > deadline:
            sys.exit(f"up.py did not start:\n{out.read_text()}")
        time.sleep(0.5)
    return proc, out


def worker_pid(out):
    text = out.read_text()
    restarted = re.findall(r"worker restarted, pid (\d+)", text)
    return int(restarted[-1]) if restarted else int(re.search(r"worker pid (\d+)", text)[1])


def pool(worker):
    try:
        return [int(p) for p in Path(f"/proc/{worker}/task/{worker}/children").read_text().split()]
    except OSError:
        return []


def wchan(pid):
    try:
        return Path(f"/proc/{pid}/wchan").read_text()
    except OSError:
        return ""


def busy_child(worker, var):
    """A pool process running a job: a job is processing and this process is not
    waiting for one (on the job pipe or its lock)."""
    if not any(status == "processing" for _, status in job_states(var)):
        return None
    for pid in pool(worker):
        if not any(idle in wchan(pid) for idle in ("pipe_read", "futex")):
            return pid
    return None


def kill(kind, out, var):
    """Kill one part of the worker; what was killed, or None if there was nothing to kill."""
    worker = worker_pid(out)
    if kind == "busy pool process":
        target = busy_child(worker, var)
    elif kind == "idle pool process holding the job-pipe lock":
        target = next((p for p in pool(worker) if "pipe_read" in wchan(p)), None)
    else:
        target = worker
    if target is None:
        return None
    try:
        if kind == "whole worker":
            os.killpg(target, signal.SIGKILL)
        else:
            os.kill(target, signal.SIGKILL)
    except ProcessLookupError:
        return None
    return kind


def review_step(client, rng, captures):
    """One annotator action on a ready capture's review (or its submission)."""
    ready = [c for c in captures if c.get("ready")]
    if not ready:
        return
    capture = rng.choice(ready)["id"]
    status, review = client.call("GET", f"/api/captures/{capture}/review/")
    if status != 200 or review["status"] != "in_progress":
        return
    version, cuts = review["version"], [c for c in review["cuts"] if c["fate"] != "deleted"]
    action = rng.choice(["move", "delete", "insert", "label", "label", "submit"])
    base = f"/api/captures/{capture}/review/"
    if action in ("move", "delete") and cuts:
        cut = rng.choice(cuts)
        body = {"fate": "deleted"} if action == "delete" else {"frame": cut["frame"] + rng.choice([-3, 3])}
        client.call("PATCH", f"{base}cuts/{cut['id']}/", {**body, "version": version})
    elif action == "insert":
        client.call("POST", f"{base}cuts/", {"frame": rng.randrange(10, 2000), "version": version})
    elif action == "label" and review["segments"]:
        segment = rng.choice(review["segments"])["index"]
        client.call("PATCH", f"{base}segments/{segment}/",
                    {"label": rng.choice(["walk", "run", "jump", None]), "version": version})
    elif action == "submit" and rng.random() < 0.2:
        client.call("POST", f"{base}submit/", {"version": version})


def refresh(client, captures):
    for capture in captures:
        if capture.get("ready"):
            continue
        status, body = client.call("GET", f"/api/captures/{capture['id']}/")
        if status == 200:
            run = body.get("latest_run") or {}
            capture["ready"] = body["status"] == "ready" and run.get("status") == "ready"


def job_states(var):
    import sqlite3

    with sqlite3.connect(var / "cutroom.sqlite3", timeout=60) as db:
        rows = db.execute(
            "SELECT 'capture', status, COUNT(*) FROM segmentation_capture GROUP BY status "
            "UNION ALL SELECT 'run', status, COUNT(*) FROM segmentation_detectionrun GROUP BY status"
        ).fetchall()
    return {(kind, status): count for kind, status, count in rows}


def main():
    args = parse_args()
    rng = random.Random(args.seed)
    folder = Path(tempfile.mkdtemp(prefix="cutroom-soak-"))
    var, port = folder / "var", args.port or free_port()
    started = time.monotonic()
    proc, out = start_up(var, port)
    client = Client(port)
    client.login("annotator")
    _, listing = client.call("GET", "/api/captures/")
    captures = [{"id": c["id"]} for c in listing["results"]]
    kinds = ["busy pool process", "idle pool process holding the job-pipe lock", "whole worker"]
    kills, uploads, refused = Counter(), 0, Counter()
    deadline = time.monotonic() + args.minutes * 60
    next_upload = next_kill = time.monotonic() + 10
    try:
        while time.monotonic() < deadline:
            now, uploaded = time.monotonic(), False
            if now >= next_upload:
                next_upload = now + args.upload_every
                content = synthetic_take(rng.randrange(10**6), rng.uniform(20, 90))
                status, body = client.upload(f"soak-{uploads}.bvh", content)
                uploads, uploaded = uploads + 1, True
                if status in (200, 201):
                    captures.append({"id": body["id"]})
                else:
                    refused[status] += 1
            if now >= next_kill and uploaded:
                # Right after an upload, so that the busy kill finds a job running.
                next_kill = now + args.kill_every
                # The busy kill waits for a job to be running (up to 30 s).
                kind = kinds[sum(kills.values()) % len(kinds)]
                for _ in range(600):
                    done = kill(kind, out, var)
                    if done or kind != "busy pool process":
                        break
                    time.sleep(0.05)
                kills[done or f"{kind} (none found)"] += 1
            refresh(client, captures)
            review_step(client, rng, captures)
            time.sleep(rng.uniform(1.0, 4.0))
        drain_deadline = time.monotonic() + args.drain
        while time.monotonic() < drain_deadline:
            states = job_states(var)
            if not any(s in ("queued", "processing") for _, s in states):
                break
            time.sleep(2)
        drained = time.monotonic() - (drain_deadline - args.drain)
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(120)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
    report(args, var, out, client, captures, uploads, kills, refused, states, drained, started)


def report(args, var, out, client, captures, uploads, kills, refused, states, drained, started):
    from cutroom import broker

    stats = broker.statistics(var / "broker" / "broker.sqlite3")
    sent = sum(q["sent"] for q in stats.values())
    acked = sum(q["acked"] for q in stats.values())
    waiting = sum(q["waiting"] for q in stats.values())
    stuck = sum(n for (_, s), n in states.items() if s in ("queued", "processing"))
    failed = sum(n for (_, s), n in states.items() if s == "failed")
    errors = sum(n for code, n in client.statuses.items() if isinstance(code, int) and code >= 500)
    no_answer = sum(n for code, n in client.statuses.items() if isinstance(code, str))
    text = out.read_text()
    worker_log = (var / "log" / "worker.log").read_text(errors="replace")
    up = up_script()
    print(f"soak: embedded default (up.py: SQLite, SQLite broker, 1 worker x 2 pool processes, "
          f"gunicorn {up.WEB_WORKERS}x{up.WEB_THREADS}, bulk lane server at nice {up.BULK_NICE}), "
          f"{args.minutes:g} min of load + drain {drained:.0f} s; "
          f"{os.cpu_count()} CPUs shared; total {time.monotonic() - started:.0f} s")
    print(f"load: {uploads} uploads (20-90 s takes at 120 fps, one per {args.upload_every:g} s), "
          f"{sum(client.statuses.values())} HTTP requests, kills every {args.kill_every:g} s:")
    for kind, n in sorted(kills.items()):
        print(f"  killed {n:3d} x {kind}")
    rows = [
        ("broker messages sent", sent),
        ("broker messages processed (acknowledged)", acked),
        ("broker messages still waiting", waiting),
        ("broker messages lost", sent - acked - waiting),
        ("jobs stuck (queued/processing after drain)", stuck),
        ("jobs failed", failed),
        ("HTTP 5xx responses", errors),
        ("HTTP requests without an answer", no_answer),
        ("worker 'Unrecoverable error'", worker_log.count("Unrecoverable error")),
        ("worker restarts by up.py", text.count("worker restarted, pid")),
        ("of which: stalls found", text.count("the worker is stuck")),
        ("up.py exited by itself", int("received; stopping" not in text)),
    ]
    width = max(len(name) for name, _ in rows)
    for name, value in rows:
        print(f"  {name:<{width}}  {value:>7}")
    print(f"  job states: {dict(sorted(states.items()))}")
    print(f"  HTTP statuses: {dict(sorted(client.statuses.items(), key=str))}")
    if refused:
        print(f"  uploads refused: {dict(refused)}")
    print(f"  logs: {var / 'log'}, up.py output: {out}")

